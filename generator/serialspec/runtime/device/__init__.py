"""Generated virtual devices: memory, motion, replies and faults, driven by data from the spec.

A generated `simulator.py` holds only data (a `DeviceSpec` built from the spec's `device:` section, its tables and
its commands); everything a device does is in this package (engine.py; faults.py; server.py serves it on a
pseudo-terminal) and is the same for every protocol:

- memory: the spec's table, initialised from its defaults (and the device section's `initial` values), then the
  device's model's factory values (`models`: the first unless another is named; its ranges replace the table's);
- a request whose address is a device's id is answered by that device, one whose address is the broadcast value is
  obeyed by every device, which stay silent unless the command says `broadcast_reply`;
- a response is built field by field: `reads` from memory, `reports` of a state variable or memory entry,
  then the request's field of the same name, then the device section's `reply` values, then 0;
- a response with `optional_when` is sent only while that parameter holds the value, and one with `after`
  once the request's field of that name (ms) has elapsed;
- `moves` makes a state variable go linearly from where it is to the request's target, over a duration or at a
  speed (trapezoidal with acceleration and deceleration ramps); reading it meanwhile gives the value on the way,
  and `moving` entries (or one bit of them) read 1 until it arrives; `stops` ends a move where it is, `wraps`
  keeps a variable within a period and `counts` reports its whole periods (turns);
- `held_while` keeps requests while a state variable is set, until a command `releases` them (or drops them,
  `cancel_when`); `carries` hands the requests a sync command holds to the devices as if sent alone;
- faults can be injected for the next replies: drop, corrupt (checksum), late, garbage, truncate, other_id;
- `each` applies a command to every item of a request group, each item addressing its own device;
- further `kinds` of device (a board's PWM servo ports, its motors) have their own ids, address field and state;
  a command names its kind; a request for an id no device has is answered with `absent` values if the command
  gives them (a board answering for a servo that is not there), else not at all;
- data `spaces` (Modbus coils and registers): runs of items read into a response field or written from a request
  field; a request whose values the device does not accept (`limits`), whose run reaches beyond its space, or
  that writes a read-only space gets the protocol's error reply (Modbus exceptions 3 and 2);
- a `timeout`: a device that has had none of its keep-alive requests for a while sets state variables (VESC
  releases its motor when setpoints stop coming);
- `derived` entries read as an expression of others (a present position with a homing offset added), and `locks`
  refuse writes to entries while a value is non-zero (EEPROM while the torque is on: `errors.locked`);
- `sends`: messages a device sends on its own, periodically, after some requests or when values change, while
  it keeps answering requests (`due()` gives them; the server sends them at their time);
- `emit()` sends a message on the device's own initiative (reports, key events) for tests.
"""

from serialspec.runtime.device.engine import (
    CommandSpec,
    CountedBlank,
    DeviceSpec,
    Engine,
    EntrySpec,
    ErrorSpec,
    KindSpec,
    ModelSpec,
    RunSpec,
    SendSpec,
    SpaceSpec,
    TimeoutSpec,
    VirtualDevice,
)
from serialspec.runtime.device.faults import FAULTS, Fault
from serialspec.runtime.device.server import Simulator

__all__ = [
    "FAULTS",
    "CommandSpec",
    "CountedBlank",
    "DeviceSpec",
    "Engine",
    "EntrySpec",
    "ErrorSpec",
    "Fault",
    "KindSpec",
    "ModelSpec",
    "RunSpec",
    "SendSpec",
    "Simulator",
    "SpaceSpec",
    "TimeoutSpec",
    "VirtualDevice",
]
