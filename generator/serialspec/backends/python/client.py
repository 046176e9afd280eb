"""Emit a protocol's typed client: one method per command and sub-command, built on runtime.transport.

Decisions made here, the same for every protocol:
- arguments and results are wire units, like the messages (the spec's `unit`/`scale` are in the docstrings);
- a method returns the reply's one field that is not an echo of the request, the whole reply when there are
  several, and True when there are none; a reply field named like an argument is an echo unless the device
  `reports` it (the level a device really set), and the fields the spec's `echoes` lists are checked against
  what was sent (EchoMismatch); a reply that does not come raises Timeout, except for a command the spec
  marks `probe` (PING), whose method returns True/False (answered or not) whatever the reply holds;
- a reply that can be absent (broadcast address, `optional_when`) makes the method return None then;
- a table that one command reads by key and another writes by key gets read_<entry>/write_<entry> by name:
  `read_parameter(id, "voltage")`;
- a command with sub-commands becomes an attribute holding a generated group class, one method per sub-command:
  `client.bus_servo.read_position(5)`;
- a response field with `status: {ok: N}` is checked (DeviceError unless it holds N) and left out of the result;
- a group whose items have exactly two fields also takes a mapping {first: second}: `set_speeds({1: -1.0})`;
- messages the device sends on its own come from `reports(timeout)` (an iterator) or `on_<report>(callback)`.
"""

from __future__ import annotations

from typing import Any, assert_never

from serialspec.backends.common.numbers import number
from serialspec.backends.common.pairing import asked_commands, request_response_pairs
from serialspec.backends.python.content import annotation, element_scalar, field_default
from serialspec.backends.python.kinds import list_item_type
from serialspec.backends.python.registers import map_name, names_alias
from serialspec.backends.python.render import one_line, render
from serialspec.backends.python.simulator import import_order
from serialspec.lang.model import (
    Array,
    Bytes,
    Direction,
    Field,
    FrameElement,
    Group,
    List,
    Message,
    Packed,
    Protocol,
    Scalar,
    Table,
    TableBlock,
    TableEntry,
    TableValue,
    Text,
    Varint,
    refusals_of,
    replies_by_request,
    reply_condition,
)

RESERVED = {"bus", "close", "subscribe", "optional_replies", "reports"}


def address_of(protocol: Protocol, request: Message | None = None) -> tuple[str, int | None]:
    """The field holding the device id and its broadcast value (for `request`: those of the kind it addresses)."""
    if protocol.device is not None:
        behaviour = protocol.device.behaviour(request.key) if request else None
        kind = next((k for k in protocol.device.kinds if behaviour and k.name == behaviour.kind), None)
        if kind is not None:
            return kind.address, kind.broadcast
        return protocol.device.address, protocol.device.broadcast
    for layout in protocol.framing.layouts.values():
        for element in layout.value_elements:
            if element.role == "address":
                return element.name, element.broadcast
    return "", None


def value_fields(protocol: Protocol, message: Message) -> list[Field]:
    """The members of a message class, frame-level values (SMS id) first, as the codec generator orders them: those
    of the layout its frames travel in (layouts chosen by command may carry different ones: STM32's Read Memory
    address)."""
    layout = protocol.layout(message)
    frame = [element_scalar(e) for e in layout.value_elements if e.type is not None]
    return [*frame, *(f for f in message.fields if not (isinstance(f, Scalar) and f.hidden))]


def type_names(f: Field) -> list[str]:
    """The generated classes a field's value is made of (the client imports them)."""
    match f:
        case Scalar():
            names = (f.bits_class, f.enum.class_name if f.enum else "", f.flags.class_name if f.flags else "")
            return [n for n in names if n]
        case Group() | TableBlock():
            return [f.class_name]
        case Varint() | Array() | Packed() | List() | Text() | Bytes() | TableValue():
            return []
        case _:
            assert_never(f)


def describe(f: Field) -> str:
    parts = [f.description or f.name.replace("_", " ")]
    unit = getattr(f, "unit", "")
    if unit:
        parts.append(f"[{unit}]")
    if isinstance(f, Scalar) and not f.bits and (f.minimum, f.maximum) != (f.type.minimum, f.type.maximum):
        parts.append(f"({number(f.minimum)}..{number(f.maximum)})")
    return one_line(" ".join(parts))


def table_commands(protocol: Protocol) -> list[dict[str, Any]]:
    """Tables some command reads by key and another writes by key: read_/write_<entry> by name."""
    address, _ = address_of(protocol)
    found = []
    for table in protocol.tables:
        reader = writer = None
        for request, response in request_response_pairs(protocol):
            names = [f.name for f in value_fields(protocol, request)]
            if response is not None:
                value = next((f for f in response.fields if isinstance(f, TableValue) and f.table is table), None)
                if value is not None and names == [address, value.key] and reader is None:
                    reader = (request, value)
            value = next((f for f in request.fields if isinstance(f, TableValue) and f.table is table), None)
            if value is not None and names == [address, value.key, value.name] and writer is None:
                writer = (request, value)
        if reader and writer:
            found.append(table_context(protocol, table, reader, writer))
    return found


def method_name(message: Message) -> str:
    name = message.key.replace(".", "_")
    return f"{name}_command" if name in RESERVED else name


def attribute_name(name: str) -> str:
    return f"{name}_command" if name in RESERVED else name


def pair_group(f: Field) -> tuple[Field, Field] | None:
    """The two fields of a group item that a mapping {first: second} can give, if the item has exactly two."""
    if not isinstance(f, Group):
        return None
    members = [g for g in f.fields if not (isinstance(g, Scalar) and g.hidden)]
    return (members[0], members[1]) if len(members) == 2 else None


def single_group(f: Field) -> Field | None:
    """The one field of a group item that a plain sequence of values can give, if the item has exactly one."""
    if not isinstance(f, Group):
        return None
    members = [g for g in f.fields if not (isinstance(g, Scalar) and g.hidden)]
    return members[0] if len(members) == 1 else None


def status_fields(message: Message) -> list[Scalar]:
    return [f for f in message.fields if isinstance(f, Scalar) and f.status_ok is not None]


def table_context(
    protocol: Protocol, table: Table, reader: tuple[Message, TableValue], writer: tuple[Message, TableValue]
) -> dict[str, Any]:
    entries = [e for e in table.entries if not e.reserved]
    return {
        "name": table.name,
        "singular": table.name[:-1] if table.name.endswith("s") else table.name,
        "upper": table.name.upper(),
        "title": one_line(table.title or table.name),
        "entries": [(e.name, e.key) for e in entries],
        "read_only": [e.name for e in entries if e.access == "r"],
        "reader": method_name(reader[0]),
        "writer": method_name(writer[0]),
        "key": reader[1].key,
    }


def status_elements(protocol: Protocol) -> list[FrameElement]:
    """The reply's frame-level status values (FEETECH `error`): the bus raises DeviceError when one is non-zero."""
    return [e for e in protocol.framing.layouts[Direction.RESPONSE].value_elements if e.role == "status"]


def unused_fields(protocol: Protocol, request: Message, response: Message) -> set[str]:
    """Reply fields that carry nothing for this request: frame status (checked by the bus, DeviceError) and a run
    of registers read from a request field this request does not have (a shared reply's `data` to a PING)."""
    unused = {e.name for e in status_elements(protocol)}
    names = {f.name for f in request.fields}
    names |= {f.name for g in request.fields if isinstance(g, Group) for f in g.fields}  # per-item (BULK READ)
    for f in response.fields:
        if isinstance(f, Bytes) and f.table is not None:
            needed = [*([f.start] if f.start_in_request else []), *([f.size_from] if f.size_from else [])]
            if not all(n in names for n in needed):
                unused.add(f.name)
    return unused


def status_flags(protocol: Protocol) -> str:
    """The reply's frame status elements that have flags, as a literal {name: flags class} (empty if none)."""
    pairs = [f"{e.name!r}: {e.flags.class_name}" for e in status_elements(protocol) if e.flags is not None]
    return "{" + ", ".join(pairs) + "}" if pairs else ""


def register_examples(table: Table) -> dict[str, str]:
    """Docstring examples from the table's own registers (never another protocol's)."""
    entries = [e for e in table.entries if not e.reserved]
    writable = [e for e in entries if e.access == "rw"][:2] or entries[:1]

    def value(e: TableEntry) -> str:
        return number(e.default if isinstance(e.default, int | float) else e.minimum)

    return {
        "write_example": ", ".join(f"{e.name}={value(e)}" for e in writable),
        "read_example": entries[0].name if entries else "",
        "each_example": ", ".join(f'{i}: {{"{writable[0].name}": {value(writable[0])}}}' for i in (1, 2))
        if writable
        else "",
    }


def register_commands(protocol: Protocol, methods: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Commands that carry a run of registers get a method by register name; the raw one keeps `<name>_raw`.

    A request with `bytes` of a table from its own start field writes (`write(id, position=100)`), a request
    whose reply holds such bytes from the request's start and size reads (`read(id, "position")`), and a
    request group whose items each hold such bytes for one device writes to several (`sync_write({1: {...}})`).
    """
    found: list[dict[str, Any]] = []
    by_name = {m["name"]: m for m in methods}
    for request, response in request_response_pairs(protocol):
        method = by_name.get(method_name(request))
        if method is None:
            continue
        address, broadcast = address_of(protocol, request)
        context = {
            "name": method["name"],
            "raw": method["name"] + "_raw",
            "returns": method["returns"],
            "address": address,
            "broadcast": broadcast,
            "title": method["doc"][0].rstrip("."),
            "id_entry": "",
        }
        run = next(
            (f for f in request.fields if isinstance(f, Bytes) and f.table and f.start and f.size == "rest"), None
        )
        group = next((f for f in request.fields if isinstance(f, Group)), None)
        item_run = (
            next((f for f in group.fields if isinstance(f, Bytes) and f.table and f.start), None) if group else None
        )
        replied = response.fields if response else ()
        read = next((f for f in replied if isinstance(f, Bytes) and f.table and f.size_from), None)
        fields = [f.name for f in value_fields(protocol, request)]
        if run is not None and run.table is not None and fields == [address, run.start, run.name]:
            context.update(kind="write", map=map_name(run.table), alias=names_alias(run.table))
            # a write of the device's own id is answered (if at all) from the new id: matched by it (not a buffered
            # write: the id changes later, on the command that commits it)
            device = protocol.device
            behaviour = device.behaviour(request.key) if device is not None else None
            id_entry = device.id_entry if device is not None and not (behaviour and behaviour.buffered) else ""
            if method["kind"] == "ack" and any(e.name == id_entry for e in run.table.entries):
                optional = method["optional"] if method["silent"] else "None"
                build = f"{address}={address}, {run.start}=start, {run.name}=data"
                context.update(id_entry=id_entry, request=method["request"], response=method["response"])
                context.update(build=build, optional=optional)
        elif read is not None and read.table is not None and group is None and len(fields) == 3:
            start, size = read.start, read.size_from
            if fields != [address, start, size]:
                continue
            # the first register read also reads the parameters that switch optional replies (one _read_key)
            first = not any(c["kind"] == "read" for c in found)
            context.update(kind="read", map=map_name(read.table), alias=names_alias(read.table), returns="int")
            context.update(read_key=first)
            # a read of one register by name, checked and encoded once per device and register, then sent as it is
            # (not where the timeout grows with a field or the method checks a status itself)
            quick = not method["after"] and not method["statuses"]
            optional = method["optional"] if method["silent"] else ""
            context.update(quick=quick, request=method["request"], response=method["response"], optional=optional)
            context.update(start=start, size=size, data=read.name)
        elif group is not None and read is not None and read.table is not None and method["kind"] == "each":
            start, size = read.start, read.size_from
            items = [f.name for f in group.fields]
            if fields == [address, start, size, group.name] and items == [address]:
                context.update(kind="each_read", map=map_name(read.table), alias=names_alias(read.table))
                context.update(group=group.name, item=group.class_name, item_address=address)
            elif fields == [address, group.name] and items == [address, start, size]:
                # every item names its own device and run (BULK READ)
                context.update(kind="items_read", map=map_name(read.table), alias=names_alias(read.table))
                context.update(group=group.name, item=group.class_name, item_address=address, start=start, size=size)
            else:
                continue
        elif (
            group is not None
            and item_run is not None
            and item_run.table is not None
            and response is None
            and item_run.start in {f.name for f in group.fields}
        ):
            if fields != [address, group.name]:
                continue
            # every item writes its own run to its own device (BULK WRITE)
            context.update(kind="items_write", map=map_name(item_run.table), alias=names_alias(item_run.table))
            context.update(group=group.name, item=group.class_name)
            context.update(item_address=address, start=item_run.start, field=item_run.name)
        elif group is not None and item_run is not None and item_run.table is not None and response is None:
            size = item_run.size if isinstance(item_run.size, str) else ""
            if fields != [address, item_run.start, *([size] if size in fields else []), group.name]:
                continue
            item_address = next(f.name for f in group.fields if f.name == address)
            context.update(
                kind="each_write",
                map=map_name(item_run.table),
                alias=names_alias(item_run.table),
                group=group.name,
                item=group.class_name,
                item_address=item_address,
                field=item_run.name,
                size=size if size in fields else "",
            )
        else:
            continue
        table = next(t for t in protocol.tables if map_name(t) == context["map"])
        context.update(register_examples(table))
        method["name"] = context["raw"]
        found.append(context)
    return found


def carry_method(protocol: Protocol, request: Message, imports: set[str]) -> dict[str, Any] | None:
    """For a request that `carries` other requests (a sync command): a method that takes those requests.

    It encodes each, takes its content as one item of the carrier's group, and collects the replies the carried
    command gets (one per request, matched by address) unless that command's reply is optional or absent.
    """
    behaviour = protocol.device.behaviour(request.key) if protocol.device else None
    if behaviour is None or behaviour.carries is None:
        return None
    group = next((f for f in request.fields if isinstance(f, Group) and f.name == behaviour.each), None)
    if group is None:
        return None
    code_field, content_field = behaviour.carries
    layout = protocol.framing.layouts[Direction.REQUEST]
    start, trailing = layout.offsets["content"], layout.overhead - layout.offsets["content"]
    replies = dict(request_response_pairs(protocol))
    carried = []
    for command in protocol.commands:
        inner = command.request
        if command.code is None or inner is None or command.subcommands or inner is request:
            continue
        if behaviour.carried and command.name not in behaviour.carried:
            continue
        reply = replies.get(inner)
        expected = reply if reply is not None and reply_condition(inner, reply) is None else None
        carried.append((inner.class_name, command.code, expected.class_name if expected else "None"))
    imports.add(group.class_name)
    title = protocol.command(request.command).title or request.key
    return {
        "name": method_name(request) + "_of",
        "params": "requests: Sequence[Message]",
        "returns": "list[Message]",
        "doc": [
            one_line(title) + ", from the requests it carries: one per device, all of one command.",
            "",
            f"Each request's content becomes one item of `{group.name}`; the command's replies (one per request, in"
            " order) are returned, or [] when that command answers only when a parameter allows it or not at all.",
        ],
        "kind": "carry",
        "carried": carried,
        "carried_name": method_name(request).upper() + "_CARRIES",
        "content": f"slice({start}, {-trailing if trailing else None})",
        "carrier": request.class_name,
        "code_field": code_field,
        "group": group.name,
        "item": group.class_name,
        "content_field": content_field,
        "pairs": [],
        "singles": [],
        "statuses": [],
    }


def client_module(protocol: Protocol) -> str:
    return render("client.py.j2", **client_context(protocol), aio=False)


def client_context(protocol: Protocol) -> dict[str, Any]:
    """What client.py.j2 needs, and the asyncio client's aio.py.j2 (both render the classes of _client_classes.j2).

    `class_imports` are the names the classes use; `imports` adds those only the module-level tables use."""
    imports: set[str] = set()  # what the classes use
    module_imports: set[str] = {"Direction"}  # what only BINDING and the module's tables use
    methods: list[dict[str, Any]] = []
    optional_keys: set[int] = set()
    tables = table_commands(protocol)
    writers = {t["writer"]: t for t in tables}
    groups: dict[str, dict[str, Any]] = {}
    # frame values the client fills in, one more per request: name -> the call that gives the next
    sequences = {
        e.name: f"self._sequence({e.name!r}, {number(e.minimum)}, {number(e.maximum)})"
        for e in protocol.framing.layouts[Direction.REQUEST].value_elements
        if e.sequence
    }
    required = False  # a parameter's default is REQUIRED (after a value of preset bit fields)
    for request, response in request_response_pairs(protocol):
        command = protocol.command(request.command)
        sub = next((s for s in command.subcommands if s.name == request.subcommand), None)
        fields = value_fields(protocol, request)
        imports.add(request.class_name)
        address, broadcast = address_of(protocol, request)
        behaviour = protocol.device.behaviour(request.key) if protocol.device else None
        params = []
        trailing = True
        defaults: dict[str, str] = {}
        for f in reversed(fields):
            if trailing and field_default(f):
                defaults[f.name] = field_default(f)
            else:
                trailing = False
        # a field with a default before fields without one (a reserved byte; a value of preset bit fields, a sync
        # byte): its default, theirs REQUIRED
        # (the message class refuses it), as the message class's parameters
        after_default = False
        for f in fields:
            if f.name in defaults or f.name in sequences:
                continue
            if field_default(f):
                defaults[f.name] = field_default(f)
                after_default = True
            elif after_default:
                defaults[f.name] = "REQUIRED"
                required = True
        pairs = []
        singles = []
        partial = protocol.framing.partial_values(Direction.REQUEST)
        for f in fields:
            if f.name in sequences:
                continue  # the client fills it in
            if f.name in partial:  # a frame value some layout lacks (a device number): None sends a frame without it
                params.append(f"{f.name}: {annotation(f)} | None")
                continue
            imports.update(type_names(f))
            default = f" = {defaults[f.name]}" if f.name in defaults else ""
            if isinstance(f, Scalar) and f.bits and defaults.get(f.name, "REQUIRED") != "REQUIRED":
                imports.add(defaults[f.name])  # the bits class's preset instance
            pair = pair_group(f)
            single = single_group(f)
            if single is not None:
                assert isinstance(f, Group)
                imports.update(type_names(single))
                params.append(f"{f.name}: {annotation(f)} | Sequence[{annotation(single)}]{default}")
                singles.append({"name": f.name, "item": f.class_name, "field": single.name})
            elif pair is not None:
                assert isinstance(f, Group)
                first, second = pair
                imports.update(type_names(first) + type_names(second))
                params.append(
                    f"{f.name}: {annotation(f)} | Mapping[{annotation(first)}, {annotation(second)}]{default}"
                )
                pairs.append({"name": f.name, "item": f.class_name, "first": first.name, "second": second.name})
            else:
                params.append(f"{f.name}: {annotation(f)}{default}")
        title = (sub.title if sub else command.title) or request.key.replace("_", " ")
        doc = [one_line(title) + ("" if title.endswith(".") else ".")]
        description = (sub.description if sub else command.description) or request.description
        if description:
            doc.append("")
            doc.append(one_line(description))
        if command.broadcast:
            doc.append("")
            doc.append("Broadcast: " + one_line(command.broadcast))
        args = [f"    {f.name}: {describe(f)}" for f in fields if f.name not in sequences]
        args += [
            f"    ({p['name']} also takes a mapping {{{p['first']}: {p['second']}}}, one entry per item.)"
            for p in pairs
        ]
        args += [f"    ({p['name']} also takes a plain sequence of {p['field']} values.)" for p in singles]
        if args:  # a method without arguments has no Args section (it had an empty one)
            doc += ["", "Args:", *args]
        # An address that can hold the broadcast value makes the reply optional, unless the device answers it anyway.
        may_broadcast = not (behaviour and behaviour.broadcast_reply) and any(
            f.name == address and isinstance(f, Scalar) and broadcast is not None and f.maximum >= broadcast
            for f in fields
        )
        optional = reply_condition(request, response)
        if optional:
            optional_keys.add(optional.key)
        # a request answered by the command whose code its field holds: the module's table of those replies
        asks = method_name(request).upper() + "_ASKS" if request.asks_in and response is None else ""
        silent = (response is None and not asks) or optional is not None or may_broadcast
        kind = "send"
        returns = "None"
        result_expr = ""
        cut = ""  # the part of a list the reply's value keeps: what the request asked
        statuses = status_fields(response) if response else []
        alternatives = protocol.reply_alternatives(request)
        echoed: list[str] = []
        if response is not None:
            imports.add(response.class_name)
            # a reply field named like one of the call's arguments repeats it and is left out of what the method
            # returns, unless the device reports it from elsewhere (`reports`: a level the device may have changed;
            # `reads`: what it keeps, TMCL's Get Axis Parameter `value` beside the request's unused `value`)
            reported = {*behaviour.reports, *behaviour.reads, *behaviour.space_reads} if behaviour else set()
            echoes = {f.name for f in fields} - reported | {f.name for f in statuses}
            echoes |= unused_fields(protocol, request, response)
            echoes |= {response.request_code} - {""}  # the request's own code, matched by the bus
            rest = [f for f in value_fields(protocol, response) if f.name not in echoes]
            # frame-level values (a reply address) only where the content has nothing left to return
            rest = [f for f in rest if f in response.fields] or rest
            # the spec's `echoes` say the reply repeats them: checked against the arguments (a derived count, which
            # the method returns, is not one)
            echoed = [name for name in behaviour.echoes if name in {f.name for f in fields}] if behaviour else []
            if command.probe and not sub:
                kind, returns = ("bool", "bool")
            elif alternatives:  # replies that share its code, told apart by their size: whichever comes, whole
                imports.update(m.class_name for m in alternatives)
                kind, result_expr = "message", "reply"
                returns = " | ".join(m.class_name for m in (response, *alternatives))
            elif not rest:
                kind, returns = ("ack", "bool")
            elif len(rest) == 1 and isinstance(rest[0], List):
                # a list comes back as a list; padding items (bits to a whole byte) are cut to the number asked
                only = rest[0]
                kind, returns = "value", f"list[{list_item_type(only)}]"
                wanted = only.count_from if any(f.name == only.count_from for f in request.fields) else ""
                cut = f"[: request.{wanted}]" if wanted else ""
                result_expr = reply_value(only, "reply", cut)
            elif len(rest) == 1:
                imports.update(type_names(rest[0]))
                kind, returns, result_expr = "value", annotation(rest[0]), reply_value(rest[0], "reply", "")
            else:
                kind, returns, result_expr = "message", response.class_name, "reply"
            if silent:
                returns = f"{returns} | None"
            doc.append("")
            if kind == "bool":
                doc.append("Returns: True if the device answered, False if it stayed silent (timeout).")
            elif kind == "ack":
                doc.append("Returns: True once the device has answered; Timeout when it does not.")
            elif kind == "value":
                doc.append(f"Returns: {rest[0].name}: {describe(rest[0])}")
            elif alternatives:
                others = ", ".join(m.class_name for m in alternatives)
                doc.append(
                    f"Returns: the {response.class_name} reply, or {others} (replies under its code, told apart by "
                    "their size)."
                )
            else:
                doc.append(f"Returns: the {response.class_name} reply.")
            if silent:
                why = one_line(response.optional) if response.optional else "broadcast gets no reply"
                doc.append(f"None when no reply is due ({why}).")
            for f in statuses:
                doc.append(f"Raises DeviceError when the reply's {f.name} is not {f.status_ok}.")
        elif asks:
            # the reply is the response of the command whose code the argument holds: looked up before a byte is
            # written (a code no command with a response has is refused)
            kind, returns, result_expr = "message", "Message", "reply"
            if silent:
                returns = "Message | None"
            doc.append("")
            doc.append(f"Returns: the reply of the command whose code {request.asks_in} holds (see {asks}).")
            if silent:
                doc.append("None when no reply is due (broadcast gets no reply).")
        else:
            doc.append("")
            doc.append("The device does not answer.")
        each_keys = ""
        each_name = behaviour.each if behaviour else ""
        each = next((f for f in request.fields if isinstance(f, Group) and f.name == each_name), None)
        if each is not None and response is not None and kind == "value":
            # Every listed device answers in turn (SYNC READ): one reply per item, matched by its address.
            kind, silent = "each", False
            returns = f"dict[int, {annotation(rest[0])}]"
            result_expr = f"{{reply.{address}: {reply_value(rest[0], 'reply', cut)} for reply in replies}}"
            each_keys = f"[{{{address!r}: item.{address}}} for item in {each.name}]"
            doc[-1] = f"Returns: {address} -> {rest[0].name} of every listed device, in the order they answer."
        table = writers.get(method_name(request))
        method = {
            "name": method_name(request),
            "params": ", ".join(params),
            "returns": returns,
            "doc": doc,
            "request": request.class_name,
            "response": (
                f"asked_reply({asks}, {request.key!r}, {request.asks_in!r}, {request.asks_in})"
                if asks
                else response.class_name
                if response
                else ""
            ),
            "asks": (
                (asks, [(c.code, c.response.class_name) for c in asked_commands(protocol) if c.response])
                if asks
                else None
            ),
            "build": ", ".join(f"{f.name}={sequences.get(f.name, f.name)}" for f in fields),
            "kind": kind,
            "silent": silent,
            "optional": f"({optional.key}, {optional.equals}, {optional.op!r})" if optional else "None",
            "after": repr(response.after) if response and response.after else "",
            "result": result_expr,
            "remember": (
                f"_remember({address}, {table['key']}, "
                f"{next(f.name for f in request.fields if isinstance(f, TableValue))})"
            )
            if table
            else "",
            "pairs": pairs,
            "singles": singles,
            "statuses": [(f.name, f.status_ok) for f in statuses],
            "echoed": tuple(echoed) if response is not None and kind != "each" else (),
            "each_keys": each_keys,
        }
        if sub is not None:
            group = groups.setdefault(
                command.name,
                {
                    "attribute": attribute_name(command.name),
                    "class_name": command.group_class,
                    "title": one_line(command.title or command.name.replace("_", " ")),
                    "methods": [],
                },
            )
            method["name"] = sub.name
            group["methods"].append(method)
        else:
            methods.append(method)
        carrier = carry_method(protocol, request, imports)
        if carrier is not None:
            methods.append(carrier)
    reports = []
    sent = {send.command for send in protocol.device.sends} if protocol.device else set()
    for message in protocol.messages():
        if message.direction == Direction.RESPONSE and (message.unsolicited or message.key in sent):
            imports.add(message.class_name)
            title = message.title or protocol.command(message.command).title or message.key
            reports.append({"name": method_name(message), "class_name": message.class_name, "title": one_line(title)})
    registers = register_commands(protocol, methods)
    flags_literal = status_flags(protocol)
    module_imports.update(e.flags.class_name for e in status_elements(protocol) if e.flags is not None)
    everything = [*methods, *(m for g in groups.values() for m in g["methods"])]
    address, broadcast = address_of(protocol)
    class_name = protocol.client_class
    errors = None
    if protocol.error_reply is not None:
        reply = protocol.command(protocol.error_reply.command).response
        assert reply is not None
        module_imports.add(reply.class_name)
        reason = next((f.name for f in reply.fields if not (isinstance(f, Scalar) and f.hidden)), "")
        reason = protocol.error_reply.status or reason  # told by its status (`error_bits`): the status says why
        codes = {c.name: c.code for c in protocol.commands if c.code is not None and c.request is not None}
        errors = {
            "response": reply.class_name,
            "code_field": protocol.error_reply.element,
            "reason_field": reason,
            "codes": "{" + ", ".join(f"{name!r}: {code:#04x}" for name, code in codes.items()) + "}",
        }
    replies = other_replies(protocol)
    module_imports.update(replies["classes"])
    module_imports.update(name for name, _ in replies["code_fields"])
    device = protocol.device
    model_map = (
        map_name(device.memory)
        if device is not None
        and device.memory is not None
        and device.models
        and any(r["map"] == map_name(device.memory) for r in registers)
        else ""
    )
    carriers = [m for m in methods if m["kind"] == "carry"]
    module_imports.update(name for m in carriers for request, _, reply in m["carried"] for name in (request, reply))
    askers = [m for m in everything if m.get("asks")]
    module_imports.update(name for m in askers for _, name in m["asks"][1])
    module_imports.discard("None")
    checks_status = any(m["statuses"] for m in everything)
    checks_echoes = any(m.get("echoed") for m in everything)
    class_transport = [
        *(["check_echoes"] if checks_echoes else []),
        *(["check_status"] if checks_status else []),
        *(["table_key"] if tables else []),
        *(["asked_reply"] if askers else []),
    ]
    return dict(
        replies=replies,
        errors=errors,
        model_map=model_map,
        model_names=", ".join(m.name for m in device.models) if device is not None else "",
        spec_path=one_line(protocol.spec_path),
        title=one_line(protocol.title),
        package=protocol.name,
        class_name=class_name,
        description=one_line(protocol.description),
        address=repr(address),
        broadcast=repr(broadcast),
        status=repr(tuple(e.name for e in status_elements(protocol))),
        status_ok=repr({e.name: frozenset(e.ok) for e in status_elements(protocol) if e.ok}),
        methods=methods,
        carriers=carriers,
        askers=[m["asks"] for m in askers],
        groups=list(groups.values()),
        registers=registers,
        status_flags=flags_literal,
        register_imports=sorted(
            {r["map"] for r in registers}
            | {r["alias"] for r in registers if r["kind"] in ("read", "each_read", "items_read")}  # reads take names
            | ({model_map + "_MODELS"} - {"_MODELS"}),
            key=import_order,
        ),
        reports=reports,
        tables=tables,
        optional_keys=sorted(optional_keys),
        imports=sorted(imports | module_imports, key=import_order),
        class_imports=sorted(imports, key=import_order),
        # the names client.py defines at module level, which aio.py imports from it
        module_names=sorted(
            [
                "BINDING",
                *(m["carried_name"] for m in carriers),
                *(m["asks"][0] for m in askers),
                *(n for t in tables for n in (t["upper"], f"{t['upper']}_READ_ONLY")),
            ],
            key=import_order,
        ),
        checks_status=checks_status,
        checks_echoes=checks_echoes,
        quick_reads=any(r.get("quick") for r in registers),
        error_imports=[
            name
            for name, used in (
                ("EncodeError", bool(tables) or any(r["kind"] != "write" for r in registers)),
                ("Timeout", any(m["kind"] == "bool" for m in everything)),
            )
            if used
        ],
        class_transport_imports=class_transport,
        transport_imports=sorted(
            [
                "Binding",
                "Bus",
                "ClientBase",
                *(["ErrorReplies"] if errors else []),
                *(["flag_names"] if flags_literal else []),
                *class_transport,
            ],
            key=import_order,
        ),
        message_imports=[
            name
            for name, used in (
                ("REQUIRED", required),
                ("Message", any(m["kind"] == "carry" for m in everything) or bool(askers)),
            )
            if used
        ],
        abc_imports=sorted(
            {
                *(["Callable", "Iterator"] if reports else []),
                *(["Mapping"] if any(m["pairs"] for m in everything) or model_map else []),
                *(
                    ["Mapping"]
                    if any(r["kind"] in ("each_write", "items_read", "items_write") for r in registers)
                    else []
                ),
                *(["Sequence"] if any(r["kind"] == "items_read" for r in registers) else []),
                *(["Iterable"] if any(r["kind"] == "each_read" for r in registers) else []),
                *(["Sequence"] if any(m["kind"] == "carry" or m["singles"] for m in everything) else []),
            }
        ),
    )


def class_tuple(names: list[str]) -> str:
    """A tuple of classes as Python source."""
    return f"({names[0]},)" if len(names) == 1 else f"({', '.join(names)})"


def other_replies(protocol: Protocol) -> dict[str, list[Any]]:
    """The Binding's replies of other commands: request class -> the reply classes of other commands that answer or
    refuse it (`answered_by`, `refused_by`; the first only where replies are matched by command), or answer it
    beside its own (`alternatives`: replies that share its code, told apart by their size); reply class -> its
    field holding the request's code (`request_code`), and the codes of the commands whose requests such replies
    answer."""
    answered: list[tuple[str, str]] = []
    refused: list[tuple[str, str]] = []
    code_fields: list[tuple[str, str]] = []
    codes: list[tuple[str, int]] = []
    alternatives: list[tuple[str, str]] = []
    classes: list[str] = []  # the reply classes in either, which the module imports
    replies = replies_by_request(protocol.messages())
    for request, response in request_response_pairs(protocol):
        refusing = refusals_of(request, replies)
        refusals = [m.class_name for m in refusing]
        asked = [c.response for c in asked_commands(protocol) if c.response] if request.asks_in else []
        sized = protocol.reply_alternatives(request)
        if sized:
            alternatives.append((request.class_name, class_tuple([m.class_name for m in sized])))
            classes += [m.class_name for m in sized]
        others = [m.class_name for m in (response, *asked, *sized, *refusing) if m and m.command != request.command]
        if others and "command" in protocol.matching:  # only matching by command needs telling
            answered.append((request.class_name, class_tuple(others)))
            classes += others
        if refusals:
            refused.append((request.class_name, class_tuple(refusals)))
            classes += refusals
        for reply in (response, *refusing):
            if reply is not None and reply.request_code and (reply.class_name, reply.request_code) not in code_fields:
                code_fields.append((reply.class_name, reply.request_code))
        command = protocol.command(request.command)
        if command.code is not None and (command.name, command.code) not in codes:
            codes.append((command.name, command.code))
    return {
        "answered_by": answered,
        "refused_by": refused,
        "alternatives": alternatives,
        "code_fields": code_fields,
        "codes": codes if code_fields else [],
        "classes": classes,
    }


def reply_value(f: Field, reply: str, cut: str) -> str:
    """The value a method returns of a reply (named `reply`) with one field to give: the field, a list as a list
    (`cut`: the slice of it the request asked for)."""
    return f"list({reply}.{f.name}{cut})" if isinstance(f, List) else f"{reply}.{f.name}"
