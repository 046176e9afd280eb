"""Emit a protocol's virtual device: the spec's `device:` section, tables and commands as data for runtime.device."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import replace
from typing import Any, assert_never

from serialspec.backends.common.numbers import number
from serialspec.backends.common.pairing import asked_commands, request_response_pairs
from serialspec.backends.python.kinds import kind, zero_bits
from serialspec.backends.python.registers import map_name, register_tables
from serialspec.backends.python.render import one_line, render
from serialspec.lang import counts, expression
from serialspec.lang.model import (
    Array,
    Bytes,
    DeviceModel,
    Direction,
    Field,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    SpaceAccess,
    TableBlock,
    TableValue,
    Text,
    Varint,
    refusals_of,
    replies_by_request,
    reply_condition,
)

#: Behaviour attributes passed to CommandSpec under the same name when they are set.
BEHAVIOUR_ARGUMENTS = (
    "kind",
    "each",
    "stores",
    "sets",
    "absent",
    "buffered",
    "commits",
    "stops",
    "increments",
    "wraps",
    "modulo",
    "restores",
    "broadcast_ignores",
    "refused_while_moving",
    "counts",
    "every_device",
    "held_while",
    "releases",
    "cancel_when",
    "carries",
    "nothing_held",
)


def carried_requests(protocol: Protocol) -> list[tuple[int, str]]:
    """(code, request class) of every request a `carries` behaviour may carry."""
    device = protocol.device
    carriers = [b for b in device.behaviours if b.carries] if device else []
    if not carriers:
        return []
    named = {name for b in carriers for name in b.carried}
    return [
        (c.code, c.request.class_name)
        for c in protocol.commands
        if c.code is not None and c.request is not None and not c.subcommands and (not named or c.name in named)
    ]


def table_fields(*messages: Message | None) -> dict[str, tuple[str, ...]]:
    """Fields (group items' too) that hold table entries: by key, as a block, or as a run of registers."""
    found: dict[str, tuple[str, ...]] = {}
    stack = [f for message in messages if message for f in reversed(message.fields)]
    while stack:
        f = stack.pop()
        match f:
            case TableValue():
                found[f.name] = ("value", f.key)
            case TableBlock():
                found[f.name] = ("block", *(e.name for e in f.entries))
            case Bytes() if f.table is not None and f.start:
                # the request's fields are the device's `given` values, so `request.address` is `address` there
                # its size: the request field `size_from` names, else a request field named as the reply's size
                # field (the engine reads the one entry at the start where the request has neither)
                sized_by = f.size if isinstance(f.size, str) and f.size != "rest" else ""
                found[f.name] = ("run", f.start, f.size_from or sized_by)
            case Group():
                stack.extend(reversed(f.fields))
                if any(isinstance(i, TableValue) for i in f.fields):  # a read fills its items, each by its key
                    found[f.name] = ("group", *(i.name for i in f.fields))
            case Scalar() | Varint() | Array() | Packed() | List() | Text() | Bytes():
                pass  # no table entries
            case _:
                assert_never(f)
    return found


def limits(request: Message) -> dict[str, tuple[float, float, tuple[int, ...]]]:
    """The request values a device checks before it acts (Modbus: quantities, coil values): every scalar whose
    range is narrower than its type's or that has an enum, and the number of items of a list whose count field
    has a range."""
    found: dict[str, tuple[float, float, tuple[int, ...]]] = {}
    counted = {f.count: f.name for f in request.fields if isinstance(f, List) and isinstance(f.count, str)}
    for f in request.fields:
        if not isinstance(f, Scalar) or f.const is not None or f.bits:
            continue
        narrower = (f.minimum, f.maximum) != (f.type.minimum, f.type.maximum)
        if f.hidden and f.name in counted and narrower:
            found[counted[f.name]] = (f.minimum, f.maximum, ())
        elif not f.hidden and (narrower or f.enum):
            allowed = tuple(v.value for v in f.enum.values) if f.enum else ()
            found[f.name] = (f.minimum, f.maximum, allowed)
    return found


def report_source(parsed: expression.Expr) -> str:
    """A reported state variable by name, or a conversion of state variables as a function of `get`."""
    if isinstance(parsed, expression.Name):
        return repr(parsed.name)
    return function_of_get(parsed)


def function_of_get(parsed: expression.Expr) -> str:
    """An expression of state variables and memory entries as a function of `get`."""
    return f"lambda get: {expression.render(parsed, lambda n: f'get({n!r})')}"


def period_source(every: int | expression.Expr) -> str:
    """`every` of a SendSpec: the period in seconds, or a function of `get` giving it in ms (`every: 1000 / rate`)."""
    return repr(every / 1000) if isinstance(every, int) else function_of_get(every)


def derived_values(request: Message, response: Message | None) -> dict[str, str]:
    """Request values its message does not hold (derived counts), for a reply to echo: name -> a function of the
    request's fields (and the values derived before it)."""
    if response is None:
        return {}
    found = {}
    for f in request.fields:  # in order: a value may use one derived before it
        if not isinstance(f, Scalar) or f.const is not None:
            continue
        if f.value is not None:
            found[f.name] = f"lambda fields: {expression.render(f.value, lambda n: f'fields[{n!r}]')}"
        elif f.derived and f.derived[0] == "count":
            found[f.name] = f"lambda fields: len(fields[{f.derived[1]!r}])"
    return found


def run_spec(run: SpaceAccess) -> str:
    args = [repr(run.space), repr(run.start)]
    if run.count:
        args.append(f"count={run.count!r}")
    if run.value is not None:
        body = expression.render(run.value, lambda n: "current" if n == "current" else f"fields[{n!r}]")
        args.append(f"value=lambda current, fields: {body}")
    if run.single:
        args.append("single=True")
    return f"RunSpec({', '.join(args)})"


def echoes(
    protocol: Protocol,
    request: Message,
    response: Message | None,
    tables: dict[str, tuple[str, ...]],
    derived: dict[str, str],
    named: tuple[str, ...],
) -> tuple[str, ...]:
    """The response fields a device copies from the request's field of the same name: those the spec names
    (`echoes`), those replies are matched by, the device address, the keys and starts of the table values a reply
    holds, and counts the request derives. Every other reply field comes from the device, never the request."""
    if response is None:
        return ()
    assert protocol.device is not None
    keys = {name for table in tables.values() if table[0] in ("value", "run") for name in table[1:3]}
    allowed = {*named, *protocol.matching, protocol.device.address, *keys, *derived}
    allowed |= {e.name for e in protocol.framing.layouts[request.direction].value_elements if e.sequence}
    layouts = protocol.framing.layouts  # plain frame values (a sequence number) are repeated like fields
    plain = [e.name for e in layouts[response.direction].value_elements if e.role == "value"]
    sent = {e.name for e in layouts[request.direction].value_elements}
    given = {f.name for f in request.fields} | set(derived) | sent
    replied = [*plain, *(f.name for f in response.fields)]
    return tuple(name for name in replied if name in allowed and name in given)


def reply_blanks(protocol: Protocol, response: Message, filled: set[str]) -> dict[str, str]:
    """The reply values a device has no value for, where its kind's blank is not 0: response fields other than the
    `filled` ones (the device fills those in itself), and frame values made of bit fields that the spec's reply and
    status values do not name (the engine fills those in bit by bit)."""
    device = protocol.device
    assert device is not None  # a simulator is made only for a spec with a device
    blanks = {f.name: kind(f).blank(least(f, response.fields)) for f in response.fields if f.name not in filled}
    named = {key.partition(".")[0] for key in (*device.reply, *device.status) if "." in key}
    layout = protocol.framing.layouts[response.direction]
    blanks |= {e.name: zero_bits(e.bits) for e in layout.value_elements if e.bits and e.name not in {*filled, *named}}
    blanks |= {e.name: "None" for e in layout.optional if e.name not in filled}  # optional elements: not sent
    return {name: blank for name, blank in blanks.items() if blank != "0"}


def bit_field_layouts(
    protocol: Protocol, kept: Iterable[str], *messages: Message | None
) -> dict[str, tuple[tuple[str, int, int], ...]]:
    """The messages' fields made of bit fields that the device keeps (those `kept` names: read, written, stored or
    reported, and any named like a memory entry or state variable) -> (bit field, lowest bit, highest bit)...: the
    device keeps such a field as one integer (a register) and answers it bit field by bit field."""
    device = protocol.device
    assert device is not None
    names = {*kept, *device.state, *(e.name for e in (device.memory.entries if device.memory else ()))}
    return {
        f.name: tuple((b.name, b.low, b.high) for b in f.bits)
        for message in messages
        if message is not None
        for f in message.fields
        if isinstance(f, Scalar) and f.bits and f.name in names
    }


def least(f: Field, siblings: tuple[Field, ...]) -> Field:
    """`f`, sized or counted by a sibling whose range starts above 0, as of that smallest size or count: its blank
    (none of it) would have a size the sizing field refuses."""
    name = f.size if isinstance(f, Bytes | Text) else f.count if isinstance(f, Group | List) else None
    if not isinstance(name, str):
        return f
    counter = next((s for s in siblings if s.name == name and isinstance(s, Scalar)), None)
    if counter is None or counter.minimum <= 0 or isinstance(f, List) and f.count_from:
        return f
    smallest = int(counter.minimum)
    if isinstance(f, Bytes | Text):
        return replace(f, size=smallest)
    assert isinstance(f, Group | List)
    return replace(f, count=smallest)


def import_order(name: str) -> tuple[int, str]:
    """The order ruff's isort gives names in one `from` import: constants, classes, others; case-insensitive."""
    return (0 if name.isupper() else 1 if name[:1].isupper() else 2, name.lower())


def model_data(model: DeviceModel) -> dict[str, Any]:
    """A model as the template's ModelSpec: its values, and its ranges where they differ from the table's."""
    return {
        "name": repr(model.name),
        "number": model.number,
        "values": [(repr(k), number(v)) for k, v in model.initial.items()],
        "ranges": [(repr(e.name), number(e.minimum), number(e.maximum)) for e in model.entries],
    }


def simulator_module(protocol: Protocol) -> str:
    device = protocol.device
    assert device is not None
    entries = []
    for entry in device.memory.entries if device.memory else ():
        default = entry.default if isinstance(entry.default, int | float) else 0
        value = device.initial.get(entry.name, default)
        entries.append(
            f"EntrySpec({entry.name!r}, {entry.key}, {number(value)}, {entry.access!r}, "
            f"{number(entry.minimum)}, {number(entry.maximum)}),"
        )
    commands: list[dict[str, Any]] = []
    imports: set[str] = set()
    for request, response in request_response_pairs(protocol):
        behaviour = device.behaviour(request.key)
        args = [request.class_name, response.class_name if response else "None"]
        imports.add(request.class_name)
        if response:
            imports.add(response.class_name)
        if behaviour:
            if behaviour.reads:
                args.append(f"reads={behaviour.reads!r}")
            if behaviour.writes:
                args.append(f"writes={behaviour.writes!r}")
            if behaviour.resets:
                args.append("resets=True")
            if behaviour.keeps:
                args.append(f"keeps={behaviour.keeps!r}")
            if behaviour.reports:
                args.append(
                    f"reports={{{', '.join(f'{k!r}: {report_source(v)}' for k, v in behaviour.reports.items())}}}"
                )
            if behaviour.moves:
                m = behaviour.moves
                args.append(f"moves={(m.state, m.target, m.duration, m.speed)!r}")
                if m.speed_scale != 1.0:
                    args.append(f"speed_scale={m.speed_scale!r}")
                if m.enabled_by:
                    args.append(f"move_enabled_by={m.enabled_by!r}")
                if m.accel or m.decel:
                    args.append(f"ramp={(m.accel, m.decel)!r}")
                if m.to is not None:
                    args.append(f"move_to={function_of_get(m.to)}")
            if behaviour.broadcast_reply:
                args.append("broadcast_reply=True")
            for name in BEHAVIOUR_ARGUMENTS:
                if getattr(behaviour, name):
                    args.append(f"{name}={getattr(behaviour, name)!r}")
            for name in ("space_reads", "space_writes"):
                runs = getattr(behaviour, name)
                if runs:
                    args.append(f"{name}={{{', '.join(f'{k!r}: {run_spec(r)}' for k, r in runs.items())}}}")
        if request.asks_in:  # the device acts as on the request of the command whose code the field holds
            asked = [(c.code, c.request.class_name) for c in asked_commands(protocol) if c.request is not None]
            imports.update(name for _, name in asked)
            table = ", ".join(f"{code:#04x}: {name}" for code, name in asked)
            args.append(f"asks=({request.asks_in!r}, {{{table}}})")
        derived = derived_values(request, response)
        refusals = refusals_of(request, replies_by_request(protocol.messages()))
        code = protocol.command(request.command).code
        for reply in (response, *refusals[:1]):
            if reply is not None and reply.request_code and code is not None:
                derived[reply.request_code] = f"lambda fields: {code:#04x}"  # the code of the request it answers
        if refusals:
            # a refused request (a value outside its range or enum, a refused write) gets the first refusal
            imports.add(refusals[0].class_name)
            args.append(f"refusal={refusals[0].class_name}")
        if derived:
            args.append(f"derived={{{', '.join(f'{k!r}: {v}' for k, v in derived.items())}}}")
        if (device.errors is not None and protocol.error_reply is not None) or refusals:
            if protocol.error_reply is not None:
                args.append(f"code={code!r}")
            checked = limits(request)
            if checked:
                shown = ", ".join(f"{k!r}: ({number(lo)}, {number(hi)}, {v!r})" for k, (lo, hi, v) in checked.items())
                args.append(f"limits={{{shown}}}")
        condition = reply_condition(request, response)
        if response and condition:
            args.append(f"optional_when=({condition.entry!r}, {condition.equals}, {condition.op!r})")
        if response and response.after:
            args.append(f"after={response.after!r}")
        tables = table_fields(request, response)
        if tables:
            args.append(f"tables={tables!r}")
        echoed = echoes(protocol, request, response, tables, derived, behaviour.echoes if behaviour else ())
        echoed += tuple(m.request_code for m in refusals[:1] if m.request_code)  # a refusal names what it refuses
        if echoed:
            args.append(f"echoes={echoed!r}")
        # what the device fills in itself: what it reads, and runs of registers (empty unless read); a table value
        # or block it does not read gets its kind's blank, as any other field
        runs = {name for name, table in tables.items() if table[0] == "run"}
        filled = {*runs, *(behaviour.reads + tuple(behaviour.space_reads) if behaviour else ())}
        blanks = reply_blanks(protocol, response, filled) if response else {}
        for refusal in refusals[:1]:  # a refusal's own fields (a NAK's text) get their blanks too
            blanks = reply_blanks(protocol, refusal, filled) | blanks
        if blanks:
            args.append(f"blanks={{{', '.join(f'{k!r}: {v}' for k, v in blanks.items())}}}")
        keeps = (*behaviour.reads, *behaviour.writes, *behaviour.stores, *behaviour.reports) if behaviour else ()
        bit_fields = bit_field_layouts(protocol, keeps, request, response)
        if bit_fields:
            args.append(f"bit_fields={bit_fields!r}")
        commands.append({"key": request.key, "args": args})
    spaces = [
        f"SpaceSpec({s.name!r}, {s.size}, {s.item is None}, {1 if s.item is None else int(s.item.maximum)}, "
        f"{s.access!r}{'' if s.item is None or not s.item.signed else f', minimum={int(s.item.minimum)}'}),"
        for s in device.spaces
    ]
    error, unwraps = "", False
    if device.errors is not None and protocol.error_reply is not None:
        reply = protocol.command(protocol.error_reply.command).response
        assert reply is not None
        imports.add(reply.class_name)
        unwraps = device.errors.unsupported is not None
        unwrap = ", unwrap=_unwrap_request" if unwraps else ""
        status = ""
        if protocol.error_reply.status:  # told by its status (`error_bits`): its bit fields, each set by a reason
            element = next(
                e
                for e in protocol.framing.layouts[Direction.RESPONSE].elements
                if e.name == protocol.error_reply.status
            )
            bits = tuple((b.name, b.low, b.high) for b in element.bits)
            status = f", status=({element.name!r}, {bits!r})"
        error = f"ErrorSpec({reply.class_name}, {protocol.error_reply.element!r}{unwrap}{status})"
    runtime = ["CommandSpec"]
    runtime += ["CountedBlank"] if any(counts.counted(f) for m in protocol.messages() for f in m.fields) else []
    runtime += ["DeviceSpec"]
    runtime += ["EntrySpec"] if entries else []
    runtime += ["ErrorSpec"] if error else []
    runtime += ["KindSpec"] if device.kinds else []
    runtime += ["ModelSpec"] if device.models else []
    runtime += ["RunSpec"] if any(b.space_reads or b.space_writes for b in device.behaviours) else []
    runtime += ["SendSpec"] if device.sends else []
    runtime += ["Simulator"]
    runtime += ["SpaceSpec"] if spaces else []
    runtime += ["TimeoutSpec"] if device.timeout else []
    timeout = ""
    if device.timeout is not None:
        kept = [protocol.command(name).request for name in device.timeout.kept_by]
        classes = ", ".join(m.class_name for m in kept if m is not None)
        imports.update(m.class_name for m in kept if m is not None)
        timeout = f"TimeoutSpec({device.timeout.after / 1000!r}, ({classes},), {device.timeout.sets!r})"
    sends = []
    for send in device.sends:
        response = next(m for m in protocol.messages() if m.direction == Direction.RESPONSE and m.key == send.command)
        imports.add(response.class_name)
        args = [response.class_name]
        if send.every:
            args.append(f"every={period_source(send.every)}")
        requests = [m for m in protocol.messages() if m.key in send.after and m.direction == Direction.REQUEST]
        if requests:
            imports.update(m.class_name for m in requests)
            args.append(f"after=({''.join(f'{m.class_name}, ' for m in requests)})")
        if send.changes:
            args.append(f"changes={send.changes!r}")
        if send.while_:
            args.append(f"while_={send.while_!r}")
        if send.step:
            args.append(f"step={send.step!r}")
        if send.values:
            args.append(f"values={{{', '.join(f'{k!r}: {report_source(v)}' for k, v in send.values.items())}}}")
        blanks = reply_blanks(protocol, response, set())
        if blanks:
            args.append(f"blanks={{{', '.join(f'{k!r}: {v}' for k, v in blanks.items())}}}")
        bit_fields = bit_field_layouts(protocol, send.values, response)
        if bit_fields:
            args.append(f"bit_fields={bit_fields!r}")
        sends.append(f"SendSpec({', '.join(args)}),")
    return render(
        "simulator.py.j2",
        derived=", ".join(f"{k!r}: {function_of_get(v)}" for k, v in device.derived.items()),
        locks=repr(device.locks) if device.locks else "",
        sends=sends,
        runtime_imports=", ".join(runtime),
        spaces=spaces,
        error=error,
        unwrap=unwraps,
        timeout=timeout,
        spec_path=one_line(protocol.spec_path),
        title=one_line(protocol.title),
        package=protocol.name,
        description=one_line(device.description),
        class_name=protocol.simulator_class,
        address=repr(device.address),
        id_entry=repr(device.id_entry),
        broadcast=repr(device.broadcast),
        state=repr(device.state),
        reply=repr(device.reply),
        errors=repr(device.errors.by_reason()) if device.errors else "",
        entries=entries,
        commands=commands,
        registers=map_name(device.memory) if device.memory in register_tables(protocol) else "",
        status=repr(device.status) if device.status else "",
        moving=repr(device.moving) if device.moving else "",
        echo_address=device.echo_address,
        models=[model_data(m) for m in device.models],
        carried=carried_requests(protocol),
        kinds=[f"KindSpec({k.name!r}, {k.address!r}, {k.ids!r}, {k.broadcast!r}, {k.state!r})," for k in device.kinds],
        imports=sorted(imports | {"Direction"}, key=import_order),
        default_ids=repr(device.ids) if len(device.ids) > 1 else f"({device.ids[0]},)",
        model_names=", ".join(m.name for m in device.models),
        default_model=device.models[0].name if device.models else "",
    )
