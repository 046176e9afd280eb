"""What AT-command modules do to a text client. A request whose answer ends with another command's response
(`answered_by: {then: ...}`): an HC-05 style module answers `AT+VERSION?` with `+VERSION:...` and then `OK`; the
client returns the reply once the `OK` has come too, so the next request does not take that `OK` for its own answer;
the simulator sends both. A device that echoes each line (`echo=True`): the echo is never the reply."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from serialspec.lang import load_protocol
from serialspec.lang.errors import SpecErrors

SPEC = """
protocol: atmodule
title: An AT-command module
serial: {baudrate: 38400}
framing:
  kind: text
  separator: ":"
  end: "\\r\\n"
commands:
  ok:
    code: OK
    response: {unsolicited: true}
  error:
    code: ERROR
    response:
      unsolicited: true
      fields:
        reason: {type: integer, range: [0, 255]}
  version_info:
    code: "+VERSION"
    response:
      unsolicited: true
      fields:
        version: {type: text}
  version:
    code: "AT+VERSION?"
    request: {answered_by: {command: version_info, then: ok, refused_by: [error]}}
  reset:
    code: "AT+RESET"
    request: {answered_by: {command: ok, refused_by: [error]}}
  access_point:
    code: "+CWLAP"
    response:
      unsolicited: true
      fields:
        ssid: {type: text}
  list_access_points:
    code: "AT+CWLAP"
    request: {answered_by: {command: access_point, then: ok, many: true, refused_by: [error]}}
device:
  state: {}
  reply: {version: "2.0-20100601", ssid: lab}
"""


@pytest.fixture(scope="module")
def module(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ModuleType]:
    from conftest import generate_and_import

    folder = tmp_path_factory.mktemp("atmodule")
    path = folder / "atmodule.yaml"
    path.write_text(SPEC, "utf-8")
    yield generate_and_import(path, folder / "out", "atmodule")
    for name in [m for m in sys.modules if m.partition(".")[0] == "atmodule"]:
        del sys.modules[name]


def test_the_answer_names_its_end(tmp_path: Path) -> None:
    path = tmp_path / "atmodule.yaml"
    path.write_text(SPEC, "utf-8")
    text = load_protocol(path).text
    assert text is not None
    assert text.answers()["AT+VERSION?"] == (("+VERSION",), ("ERROR",), ("OK",))
    assert text.answers()["AT+RESET"] == (("OK",), ("ERROR",))  # no `then`: as before


def test_the_client_waits_for_the_ok_and_the_next_request_gets_its_own(module: ModuleType) -> None:
    """Against the simulator, which sends `+VERSION:...` then `OK`: the version comes back, and the reset after it
    is answered by its own `OK` (without `then`, the version's `OK` would be read as the reset's answer: that the
    reset's `OK` is its own shows in the nothing left unread after it)."""
    simulator = importlib.import_module("atmodule.simulator").SIMULATOR()
    try:
        with module.Client(simulator.start()) as client:
            reply = client.version(timeout=5)
            assert isinstance(reply, module.VersionInfoResponse) and reply.version == "2.0-20100601"
            assert isinstance(client.reset(timeout=5), module.OkResponse)
            assert client.read(0.3) == []
    finally:
        simulator.close()


@pytest.mark.parametrize(
    ("answer", "ssids"),
    [(b"+CWLAP:lab\r\n+CWLAP:office\r\nOK\r\n", ["lab", "office"]), (b"OK\r\n", []), (None, ["lab"])],
)
def test_a_reply_any_number_of_times_before_the_end(module: ModuleType, answer: bytes | None, ssids: list[str]) -> None:
    """`many: true`: the method returns every `+CWLAP` line before the `OK` (none when the `OK` comes at once; the
    simulator sends one)."""
    from pty_pair import answering_line

    if answer is None:
        simulator = importlib.import_module("atmodule.simulator").SIMULATOR()
        try:
            with module.Client(simulator.start()) as client:
                found = client.list_access_points(timeout=5)
        finally:
            simulator.close()
    else:
        with answering_line(b"AT+CWLAP\r\n", answer) as name, module.Client(name) as client:
            found = client.list_access_points(timeout=2)
    assert isinstance(found, tuple) and [ap.ssid for ap in found] == ssids


def test_replies_without_the_line_that_ends_them_time_out_saying_so(module: ModuleType) -> None:
    from pty_pair import answering_line
    from serialspec.runtime.errors import Timeout

    with (
        answering_line(b"AT+CWLAP\r\n", b"+CWLAP:lab\r\n") as name,
        module.Client(name) as client,
        pytest.raises(Timeout, match=r"its reply came, but not the 'OK' that ends the answer"),
    ):
        client.list_access_points(timeout=0.5)


@pytest.mark.parametrize(
    ("answer", "raised"),
    [
        (b"ERROR:29\r\n", r"^version \(AT\+VERSION\?\): the device refused it"),
        (b"+VERSION:2.0\r\nERROR:1\r\n", r"^version \(AT\+VERSION\?\): the device refused it"),
        (b"OK\r\n", r"^version \(AT\+VERSION\?\): the device ended its answer .* without a reply"),
        (b"+VERSION:2.0\r\n", r"^version \(AT\+VERSION\?\): its reply came, but not the 'OK' that ends the answer"),
    ],
)
def test_a_refusal_an_answer_without_its_reply_or_without_its_end(
    module: ModuleType, answer: bytes, raised: str
) -> None:
    from pty_pair import answering_line
    from serialspec.runtime.errors import DeviceError, Timeout

    error = Timeout if answer.endswith(b"2.0\r\n") else DeviceError
    with (
        answering_line(b"AT+VERSION?\r\n", answer) as name,
        module.Client(name) as client,
        pytest.raises(error, match=raised),
    ):
        client.version(timeout=0.5)


@pytest.mark.parametrize(
    ("then", "said"),
    [
        ("okay", "commands.version.request.answered_by.then: 'okay' is not a command with a response"),
        ("version_info", "commands.version.request.answered_by.then: 'version_info' is the reply or a refusal"),
        ("error", "commands.version.request.answered_by.then: 'error' is the reply or a refusal"),
        ("", "commands.version.request.answered_by.many: `many` needs `then`: the response that ends the replies"),
    ],
)
def test_then_mistakes_are_one_line_each(tmp_path: Path, then: str, said: str) -> None:
    path = tmp_path / "atmodule.yaml"
    mistake = f"then: {then}," if then else "many: true,"
    path.write_text(SPEC.replace("then: ok,", mistake, 1), "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(path)
    lines = str(caught.value).splitlines()
    assert len(lines) == 1 and said in lines[0], lines


def test_a_binary_spec_is_told_then_is_for_text_frames(tmp_path: Path) -> None:
    from conftest import ROOT

    spec = (ROOT / "specs" / "ubx.yaml").read_text("utf-8")
    changed = spec.replace(
        "answered_by: {command: ack_ack, refused_by: [ack_nak]}",
        "answered_by: {command: ack_ack, refused_by: [ack_nak], then: ack_ack}",
        1,
    )
    assert changed != spec
    path = tmp_path / "ubx.yaml"
    path.write_text(changed, "utf-8")
    with pytest.raises(SpecErrors) as caught:
        load_protocol(path)
    lines = str(caught.value).splitlines()
    assert len(lines) == 1 and "answered_by.then: `then` and `many` are for text frames" in lines[0], lines


ECHOED = """
protocol: echoing
title: A supply that echoes each line (echo on)
serial: {baudrate: 9600}
framing: {kind: text, separator: "=", end: "\\r\\n"}
commands:
  set_voltage:
    code: SV
    request: {fields: {volts: {type: decimal, precision: 2, range: [0, 30]}}}
    response: {fields: {volts: {type: decimal, precision: 2, range: [0, 30]}}}
device:
  state: {supply: 5}
  commands:
    set_voltage: {reports: {volts: supply}}
"""


def test_a_device_that_echoes_each_line(tmp_path: Path) -> None:
    """A request and its reply written alike (`SV=12.00` answered by `SV=5.00`, the voltage set): with the device
    echoing each line, `echo=True` takes the echo out, and the reply is the device's; without it the echo itself
    would be read as the reply. An echo that differs from the line written is a PortError."""
    from conftest import generate_and_import
    from pty_pair import answering_line
    from serialspec.runtime.errors import PortError

    path = tmp_path / "echoing.yaml"
    path.write_text(ECHOED, "utf-8")
    echoing = generate_and_import(path, tmp_path / "out", "echoing")
    simulator = importlib.import_module("echoing.simulator").SIMULATOR()
    simulator.echo = True
    try:
        with echoing.Client(simulator.start(), echo=True) as client:
            assert float(client.set_voltage(12, timeout=5).volts) == 5.0
            assert float(client.set_voltage(7, timeout=5).volts) == 5.0
            assert client.read(0.3) == []
    finally:
        simulator.close()
        for name in [m for m in sys.modules if m.partition(".")[0] == "echoing"]:
            del sys.modules[name]
    with (
        answering_line(b"SV=12.00\r\n", b"SV=13.00\r\nSV=5.00\r\n") as name,
        echoing.Client(name, echo=True) as client,
        pytest.raises(PortError, match="the echo differs from the line written"),
    ):
        client.set_voltage(12, timeout=1)
