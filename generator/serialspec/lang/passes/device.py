"""The `device:` section: how a virtual device behaves, checked against the commands it answers."""

from __future__ import annotations

from collections.abc import Container, Mapping
from typing import Any

from serialspec.lang import expression
from serialspec.lang.errors import SpecError, listed
from serialspec.lang.expression import Expr
from serialspec.lang.loader import Path
from serialspec.lang.model import (
    SCALARS,
    Array,
    Behaviour,
    Bytes,
    Command,
    Device,
    DeviceErrors,
    DeviceKind,
    DeviceModel,
    DeviceTimeout,
    Direction,
    Field,
    FrameElement,
    Framing,
    Group,
    List,
    Message,
    ModelEntry,
    Motion,
    Packed,
    Presence,
    Scalar,
    Space,
    SpaceAccess,
    Table,
    TableBlock,
    TableEntry,
    TableValue,
    Unsolicited,
    Varint,
    replies_by_request,
    reply_to,
)
from serialspec.lang.passes.base import Pass


class _Everything:
    """Contains every name: what an unknown kind or group is checked against (it is reported once itself)."""

    def __contains__(self, name: object) -> bool:
        return True


EVERYTHING = _Everything()


class DevicePass(Pass):
    """Resolve `device:` (when the framing resolved: the device's address defaults to a frame element)."""

    def run(self) -> list[SpecError]:
        data, framing = self.ctx.data, self.ctx.framing
        if "device" in data and framing is not None and isinstance(data.get("serial") or {}, dict):
            self.ctx.device = self.guard(
                ("device",), self.device, data["device"], ("device",), self.ctx.commands, framing
            )
        return self.problems

    def device(self, value: dict[str, Any], path: Path, commands: list[Command], framing: Framing) -> Device:
        memory = self.reference("table", self.tables, value.get("memory"), (*path, "memory"))
        entries = {e.name: e for e in memory.entries} if memory else {}
        for name, initial in (value.get("initial") or {}).items():
            if name not in entries:
                self.error((*path, "initial", name), f"unknown memory entry {name!r}")
            elif not entries[name].minimum <= initial <= entries[name].maximum:
                entry = entries[name]
                self.error(
                    (*path, "initial", name),
                    f"initial value {initial} is outside {name}'s range {entry.minimum:g}..{entry.maximum:g}",
                )
        address_element = next(
            (e for layout in framing.layouts.values() for e in layout.value_elements if e.role == "address"), None
        )
        address = str(value.get("address") or (address_element.name if address_element else ""))
        # a protocol without an address element (VESC) has one device per port: then no address is needed
        broadcast = value.get("broadcast", address_element.broadcast if address_element else None)
        id_entry = str(value.get("id_entry", ""))
        if id_entry and id_entry not in entries and id_entry not in (value.get("state") or {}):
            self.error((*path, "id_entry"), f"unknown memory entry or state variable {id_entry!r}")
        state = {str(k): float(v) for k, v in (value.get("state") or {}).items()}
        requests = {m.key: m for c in commands for m in c.messages() if m.direction == Direction.REQUEST}
        spaces = self.spaces(value.get("spaces") or {}, (*path, "spaces"))
        errors = self.errors(value.get("errors"), (*path, "errors"), commands)
        replies = replies_by_request(m for c in commands for m in c.messages())
        kinds = {
            str(name): DeviceKind(
                str(name),
                str(kind.get("description", "")),
                str(kind["address"]),
                tuple(int(i) for i in kind["ids"]),
                kind.get("broadcast"),
                {str(k): float(v) for k, v in (kind.get("state") or {}).items()},
            )
            for name, kind in (value.get("kinds") or {}).items()
        }
        self.check_ids(value, path, commands, framing)
        broken = self.ctx.broken
        behaviours = []
        for key, item in (value.get("commands") or {}).items():
            item_path = (*path, "commands", key)
            request = requests.get(key)
            if request is None and key in self.ctx.broken:
                continue  # the command failed to resolve: its problem is reported
            if request is None:
                self.error(item_path, f"unknown command {key!r} (or it has no request)")
                continue
            kind_name = str(item.get("kind", ""))
            if kind_name and kind_name not in kinds:
                self.error((*item_path, "kind"), f"unknown device kind {kind_name!r} (not in `kinds:`)")
            # an unknown kind or group is reported once: the names that depend on it are not checked
            known_state: dict[str, float] | _Everything = (
                kinds[kind_name].state if kind_name in kinds else EVERYTHING if kind_name else state
            )
            response = reply_to(request, replies)
            each = str(item.get("each", ""))
            group = next((f for f in request.fields if isinstance(f, Group) and f.name == each), None)
            if each and group is None:
                self.error((*item_path, "each"), f"{key} has no group field {each!r}")
            item_fields = group.fields if group else ()
            request_set = {f.name for f in (*request.fields, *item_fields)} | broken
            request_names: Container[str] = EVERYTHING if each and group is None else request_set
            response_names = ({f.name for f in response.fields} if response else set()) | broken
            space_reads = self.space_runs(
                item.get("reads"), response_names, request, spaces, (*item_path, "reads"), response
            )
            space_writes = self.space_runs(item.get("writes"), request_set, request, spaces, (*item_path, "writes"))
            for name in item.get("reads") or () if not space_reads else ():
                if name not in response_names:
                    self.error((*item_path, "reads"), f"{key} has no response field {name!r}")
            for name in item.get("writes") or () if not space_writes else ():
                if name not in request_names:
                    self.error((*item_path, "writes"), f"{key} has no request field {name!r}")
                    continue
                written = next((f for f in (*request.fields, *item_fields) if f.name == name), None)
                holds_registers = isinstance(written, (TableValue, TableBlock)) or (
                    isinstance(written, Bytes) and written.table is not None
                )
                command_path = ("commands", *key.split(".", 1)[:1])
                reported = any(p[:2] == command_path for p in self.ctx.reported)  # its fields' own problems first
                plain = written is not None and not holds_registers and not reported
                if plain and name not in entries and name not in known_state:
                    self.error(
                        (*item_path, "writes"),
                        f"{key} writes {name!r}, which is no memory entry or state variable and holds no registers "
                        "(give the field `table:` and `start:`, or name it after a memory entry)",
                    )
            reports: dict[str, expression.Expr] = {}
            for field_name, source in ((str(k), str(v)) for k, v in (item.get("reports") or {}).items()):
                if field_name not in response_names:
                    self.error((*item_path, "reports", field_name), f"{key} has no response field {field_name!r}")
                try:
                    reports[field_name] = expression.parse(source)
                except expression.ExpressionError as exc:
                    self.error((*item_path, "reports", field_name), str(exc))
                    continue
                used = set(expression.names(reports[field_name]))
                for name in sorted(n for n in used if n not in known_state and n not in entries):
                    self.error((*item_path, "reports", field_name), f"unknown state variable {name!r}")
            motion = None
            if "moves" in item:
                moves = item["moves"]
                motion = Motion(
                    str(moves["state"]),
                    str(moves["target"]),
                    str(moves.get("duration", "")),
                    str(moves.get("speed", "")),
                    float(moves.get("speed_scale", 1.0)),
                    str(moves.get("enabled_by", "")),
                    str(moves.get("accel", "")),
                    str(moves.get("decel", "")),
                    self.expression(
                        moves.get("to"), (*item_path, "moves", "to"), (request_names, entries, known_state)
                    ),
                )
                if motion.speed_scale <= 0:
                    self.error((*item_path, "moves", "speed_scale"), "must be positive")
                if motion.enabled_by and motion.enabled_by not in known_state and motion.enabled_by not in entries:
                    self.error((*item_path, "moves", "enabled_by"), f"unknown memory entry {motion.enabled_by!r}")
                if motion.state not in known_state and motion.state not in entries:
                    self.error((*item_path, "moves", "state"), f"unknown state variable {motion.state!r}")
                for role in ("target", "duration", "speed", "accel", "decel"):
                    name = getattr(motion, role)
                    if name and name not in request_names and name not in entries and name not in known_state:
                        self.error(
                            (*item_path, "moves", role),
                            f"{key} has no request field, memory entry or state variable {name!r}",
                        )
            stores = {str(k): str(v) for k, v in (item.get("stores") or {}).items()}
            sets = {str(k): float(v) for k, v in (item.get("sets") or {}).items()}
            absent = {str(k): float(v) for k, v in (item.get("absent") or {}).items()}
            for field_name, target in stores.items():
                if field_name not in request_names:
                    self.error((*item_path, "stores", field_name), f"{key} has no request field {field_name!r}")
                if target not in known_state and target not in entries:
                    self.error((*item_path, "stores", field_name), f"unknown state variable {target!r}")
            for target in sets:
                if target not in known_state and target not in entries:
                    self.error((*item_path, "sets", target), f"unknown state variable {target!r}")
            for field_name in absent:
                if field_name not in response_names:
                    self.error((*item_path, "absent", field_name), f"{key} has no response field {field_name!r}")
            behaviours.append(
                Behaviour(
                    key,
                    () if space_reads else tuple(item.get("reads") or ()),
                    () if space_writes else tuple(item.get("writes") or ()),
                    bool(item.get("resets", False)),
                    reports,
                    motion,
                    bool(item.get("broadcast_reply", False)),
                    each,
                    bool(item.get("buffered", False)),
                    bool(item.get("commits", False)),
                    kind_name,
                    stores,
                    sets,
                    absent,
                    space_reads,
                    space_writes,
                    self.keeps(item.get("keeps"), request_names, entries, (*item_path, "keeps")),
                    **self.behaviour_extras(
                        item,
                        item_path,
                        key,
                        request_names,
                        response_names,
                        known_state if isinstance(known_state, _Everything) else {**entries, **known_state},
                    ),
                    nothing_held={str(k): float(v) for k, v in (item.get("nothing_held") or {}).items()},
                    echoes=self.echoes(item, item_path, key, request_names, response_names),
                )
            )
        status = {str(k): str(v) for k, v in (value.get("status") or {}).items()}
        for field_name, entry_name in status.items():
            if entry_name not in entries:
                self.error((*path, "status", field_name), f"unknown memory entry {entry_name!r}")
        variables: Container[str] = {*entries, *state}
        return Device(
            derived={
                str(name): parsed
                for name, source in (value.get("derived") or {}).items()
                if self.known(name, entries, (*path, "derived", name), "memory entry")
                for parsed in [self.expression(source, (*path, "derived", name), (variables,))]
                if parsed is not None
            },
            # a derived entry reads others, never a derived one: no chain, no loop
            **self.no_chains(value.get("derived") or {}, (*path, "derived")),
            locks=self.locks(value.get("locks") or (), (*path, "locks"), entries, variables),
            sends=self.sends(
                value.get("sends") or {},
                (*path, "sends"),
                requests,
                {m.key: m for c in commands for m in c.messages() if m.direction == Direction.RESPONSE},
                variables,
            ),
            description=str(value.get("description", "")),
            memory=memory,
            initial={str(k): float(v) for k, v in (value.get("initial") or {}).items()},
            address=address,
            id_entry=id_entry,
            broadcast=broadcast,
            state=state,
            reply={str(k): reply_value(v) for k, v in (value.get("reply") or {}).items()},
            behaviours=tuple(behaviours),
            status=status,
            kinds=tuple(kinds.values()),
            echo_address=bool(value.get("echo_address", False)),
            ids=tuple(int(i) for i in value.get("ids") or (0,)),
            timeout=self.timeout(value.get("timeout"), (*path, "timeout"), requests, state),
            spaces=tuple(spaces.values()),
            errors=errors,
            models=self.models(value, path, entries, state),
            moving=self.moving(value, path, entries, state),
            model_entry=str(value.get("model_entry", "")),
            presence=self.presence(
                value.get("presence"),
                (*path, "presence"),
                (address, broadcast, self.id_bounds(value, address, framing, commands)),
                requests,
                replies,
                memory,
                str(value.get("model_entry", "")),
            ),
        )

    def known(self, name: str, names: Container[str], path: Path, what: str) -> bool:
        if name not in names:
            self.error(path, f"unknown {what} {name!r}")
        return name in names

    def expression(self, source: Any, path: Path, names: tuple[Container[str], ...]) -> expression.Expr | None:
        """An expression of the given names (request fields, memory entries, state variables), or None."""
        if source is None:
            return None
        try:
            parsed = expression.parse(str(source))
        except expression.ExpressionError as exc:
            self.error(path, str(exc))
            return None
        for name in sorted(set(expression.names(parsed))):
            if not any(name in known for known in names):
                self.error(path, f"unknown name {name!r} (not a request field, memory entry or state variable)")
        return parsed

    def period(self, value: Any, path: Path, names: tuple[Container[str], ...]) -> int | Expr:
        """`every`: a period in ms, or an expression of state variables and memory entries giving it (a rate
        register); a constant expression is its value, which must be positive."""
        if not isinstance(value, str):
            return int(value)
        parsed = self.expression(value, path, names)
        if parsed is None:
            return 0
        if isinstance(parsed, expression.Const):
            if parsed.value < 1:
                self.error(path, f"a period of {parsed.value} ms: it must be at least 1")
                return 0
            return int(parsed.value)
        return parsed

    def no_chains(self, value: dict[str, Any], path: Path) -> dict[str, Any]:
        for name, source in value.items():
            try:
                used = set(expression.names(expression.parse(str(source))))
            except expression.ExpressionError:
                continue  # reported with the entry
            for other in sorted(used & set(value)):
                self.error((*path, name), f"{name} reads the derived entry {other!r}: derive it from plain values")
        return {}

    def locks(
        self, value: Any, path: Path, entries: dict[str, TableEntry], variables: Container[str]
    ) -> dict[str, str]:
        """`locks:` as memory entry -> the variable that locks it while non-zero."""
        found: dict[str, str] = {}
        for index, item in enumerate(value):
            locker = str(item["while"])
            self.known(locker, variables, (*path, index, "while"), "memory entry or state variable")
            names = [e.name for e in entries.values() if item.get("memory") and e.memory == item["memory"]]
            for name in item.get("entries") or ():
                if self.known(str(name), entries, (*path, index, "entries"), "memory entry"):
                    names.append(str(name))
            if not names:
                self.error((*path, index), "locks no memory entry (give `memory` or `entries`)")
            # read-only entries are refused anyway: only writable ones are locked
            found |= {name: locker for name in names if name != locker and entries[name].access != "r"}
        return found

    def sends(
        self,
        value: dict[str, Any],
        path: Path,
        requests: dict[str, Message],
        responses: dict[str, Message],
        variables: Container[str],
    ) -> tuple[Unsolicited, ...]:
        """`sends:` what the device sends on its own: a command's response, and when."""
        found = []
        for key, item in value.items():
            where = (*path, key)
            response = responses.get(key)
            if response is None:
                if key not in self.ctx.broken:
                    self.error(where, f"unknown command {key!r} (or it has no response)")
                continue
            for index, name in enumerate(item.get("after") or ()):
                if name not in requests:
                    self.error((*where, "after", index), f"unknown command {name!r} (or it has no request)")
            for index, name in enumerate(item.get("changes") or ()):
                self.known(str(name), variables, (*where, "changes", index), "memory entry or state variable")
            if "step" in item:
                self.known(str(item["step"]), variables, (*where, "step"), "memory entry or state variable")
            if "while" in item:
                self.known(str(item["while"]), variables, (*where, "while"), "memory entry or state variable")
            if not any(k in item for k in ("every", "after", "changes")):
                self.error(where, "says not when: give `every`, `after` or `changes`")
            fields = {f.name for f in response.fields}
            if self.ctx.framing is not None:  # and the plain frame values every response carries (a sequence number)
                layout = self.ctx.framing.layouts[response.direction]
                fields |= {e.name for e in layout.value_elements if e.role == "value"}
            values = {}
            for name, source in (item.get("values") or {}).items():
                if self.known(str(name), fields, (*where, "values", name), f"{response.command} response field"):
                    parsed = self.expression(source, (*where, "values", name), (variables,))
                    if parsed is not None:
                        values[str(name)] = parsed
            found.append(
                Unsolicited(
                    str(key),
                    self.period(item.get("every", 0), (*where, "every"), (variables,)),
                    tuple(str(n) for n in item.get("after") or ()),
                    tuple(str(n) for n in item.get("changes") or ()),
                    str(item.get("while", "")),
                    values,
                    str(item.get("description", "")),
                    str(item.get("step", "")),
                )
            )
        return tuple(found)

    def id_bounds(
        self, value: dict[str, Any], address: str, framing: Framing, commands: list[Command]
    ) -> tuple[int, int]:
        """The ids a device may have: its address element's or field's range (else 0..255)."""
        elements = (e for layout in framing.layouts.values() for e in layout.value_elements if e.name == address)
        fields = (f for c in commands for m in c.messages() for f in m.fields if f.name == address)
        found = next(elements, None) or next(fields, None)
        low, high = getattr(found, "minimum", None), getattr(found, "maximum", None)
        return (0 if low is None else int(low), 255 if high is None else int(high))

    def presence(
        self,
        value: Any,
        path: Path,
        address: tuple[str, int | None, tuple[int, int]],
        requests: dict[str, Message],
        replies: dict[str, Message],
        memory: Table | None,
        model_entry: str,
    ) -> Presence | None:
        """`presence:`: the request every device answers (its id in the device's address), and where the model is."""
        if value is None:
            return None
        address_name, broadcast, (low, high) = address
        key = str(value["request"])
        request = requests.get(key)
        if request is None:
            if key not in self.ctx.broken:
                self.error((*path, "request"), f"unknown command {key!r} (or it has no request)")
            return None
        carries = self.carried_by(request)
        id_field = address_name if address_name in carries else ""
        fields = self.preset(value.get("fields"), (*path, "fields"), key, carries, id_field)
        self.unset(request, {*fields, id_field}, (*path, "fields"), key)
        ids: tuple[int, int] | None = None
        if id_field:
            first, last = value.get("ids") or (low, high if broadcast != high else high - 1)
            for index, number in enumerate((first, last)):
                if not low <= number <= high:
                    self.error((*path, "ids", index), f"id {number} is outside the id range {low}..{high}")
            if first > last:
                self.error((*path, "ids"), f"the first id {first} is above the last {last}")
            ids = (int(first), int(last))
        elif "ids" in value:
            self.error((*path, "ids"), f"{key} carries no device id ({address_name or 'the device has no address'})")
        if value.get("broadcast") and (broadcast is None or not id_field):
            self.error((*path, "broadcast"), "the device has no broadcast id (device.broadcast)")
        model = value.get("model") or {}
        model_key = str(model.get("request", key)) if model else ""
        model_request = requests.get(model_key) if model else None
        model_fields: dict[str, float] = {}
        register = None
        if model and model_request is None:
            self.error((*path, "model", "request"), f"unknown command {model_key!r} (or it has no request)")
        elif model_request is not None:
            reply = reply_to(model_request, replies)
            model_fields = self.preset(
                model.get("fields"), (*path, "model", "fields"), model_key, self.carried_by(model_request), id_field
            )
            name = str(model["field"])
            found = next((f for f in reply.fields if f.name == name), None) if reply else None
            if found is None:
                self.error((*path, "model", "field"), f"the reply to {model_key} has no field {name!r}")
            elif isinstance(found, Bytes) and found.table is not None:
                register = next((e for e in found.table.entries if e.name == model_entry), None)
                if register is None:
                    self.error(
                        (*path, "model", "field"),
                        f"{name!r} holds registers of {found.table.name}: device.model_entry must name one of them",
                    )
        return Presence(
            request=key,
            fields=fields,
            id_field=id_field,
            ids=ids,
            broadcast=bool(value.get("broadcast", False)),
            model_request=model_key,
            model_fields=model_fields,
            model_field=str(model.get("field", "")),
            model_register=register,
            description=str(value.get("description", "")),
        )

    def request_values(self, request: Message) -> dict[str, Field | FrameElement]:
        """The values a request carries: its content fields and the frame's values (address, status, a plain
        value such as a sync byte), except a sequence number, which the client fills in."""
        framing = self.ctx.framing
        layouts = framing.layouts.values() if framing is not None else ()
        found: dict[str, Field | FrameElement] = {
            e.name: e
            for layout in layouts
            for e in layout.value_elements
            if Direction.REQUEST in e.directions and not e.sequence
        }
        return found | {f.name: f for f in request.fields}

    def carried_by(self, request: Message) -> set[str]:
        """The names of the values a request carries (request_values)."""
        return set(self.request_values(request))

    def preset(self, value: Any, path: Path, key: str, carried: set[str], id_field: str) -> dict[str, float]:
        """Request values given by name, a bit field as `field.bit_field` (`sync.nibble`)."""
        found = {}
        for name, number in (value or {}).items():
            base, _, bit = str(name).partition(".")
            if base == id_field:
                self.error((*path, name), f"{name!r} is the device id: `scan` sets it")
            elif base not in carried:
                self.error((*path, name), f"{key} has no request field {base!r}")
            elif bit and bit not in self.bit_names(base):
                self.error((*path, name), f"{base!r} has no bit field {bit!r}")
            found[str(name)] = float(number)
        return found

    def bit_names(self, name: str) -> set[str]:
        """The bit fields of a request field or frame value of that name (any request's)."""
        framing = self.ctx.framing
        layouts = framing.layouts.values() if framing is not None else ()
        found = [e.bits for layout in layouts for e in layout.value_elements if e.name == name]
        found += [
            f.bits
            for c in self.ctx.commands
            for m in c.messages()
            for f in m.fields
            if f.name == name and isinstance(f, Scalar)
        ]
        return {b.name for bits in found for b in bits}

    def unset(self, request: Message, given: set[str], path: Path, key: str) -> None:
        """One error naming the values a presence request needs that neither `fields` nor the spec gives (a default,
        a constant, a value derived from others): `scan` could not build the request."""
        named = {name.partition(".")[0] for name in given}
        # a frame element with a mistake of its own reported already is not reported again here
        named |= {str(p[p.index("elements") + 1]) for p in self.ctx.reported if "elements" in p[:-1]}
        missing = [
            name
            for name, f in self.request_values(request).items()
            if name not in named
            and not (isinstance(f, Scalar) and (f.hidden or f.default is not None))
            and not (isinstance(f, Varint) and f.default is not None)
            and not (isinstance(f, FrameElement) and f.type is None)
        ]
        if missing:
            bits = [f"{name}.{b}" for name in missing for b in sorted(self.bit_names(name))]
            hint = f" (bit fields as {', '.join(bits)})" if bits else ""
            self.error(path, f"the {key} request needs a value for {', '.join(missing)}: give it here{hint}")

    def check_ids(self, value: dict[str, Any], path: Path, commands: list[Command], framing: Framing) -> None:
        """`address` (and each kind's) names an integer the requests carry; `reply`, `refused`, `status` name what
        the responses carry."""
        elements = {e.name: e for layout in framing.layouts.values() for e in layout.value_elements}
        carried: dict[Direction, dict[str, Field]] = {Direction.REQUEST: {}, Direction.RESPONSE: {}}
        every: dict[str, list[tuple[Message, Field]]] = {}  # response field -> each response carrying it
        for command in commands:
            for message in command.messages():
                stack = list(message.fields)
                while stack:
                    f = stack.pop()
                    carried[message.direction].setdefault(f.name, f)
                    if message.direction == Direction.RESPONSE:
                        every.setdefault(f.name, []).append((message, f))
                    if isinstance(f, Group):
                        stack.extend(f.fields)
        wanted = [((*path, "address"), value.get("address"))]
        wanted += [
            ((*path, "kinds", k, "address"), kind.get("address")) for k, kind in (value.get("kinds") or {}).items()
        ]
        for where, name in wanted:
            if name is None or name in elements:
                continue
            found = carried[Direction.REQUEST].get(name)
            if found is None:
                self.error(where, f"unknown field {name!r}: no request carries it (nor the frame)")
            elif not isinstance(found, Scalar) or found.type.is_float:
                self.error(where, f"{name!r} is no integer field, so it cannot hold a device id")
        # Reply values: `reply`, `status`, and `errors` where no error reply carries them (else `errors` checks them).
        named: list[tuple[Path, Any]] = [((key,), value.get(key)) for key in ("reply", "status")]
        if not any(m.error_reply for c in self.ctx.commands for m in c.messages()):
            named += [(("errors", reason), values) for reason, values in (value.get("errors") or {}).items()]
        for where, values in named:
            for name, given in (values or {}).items():
                head, _, bit = str(name).partition(".")  # `error.number`: a bit field of a value or element
                at = (*path, *where, name)
                element = elements.get(head)
                owners: list[tuple[str, Field | FrameElement]] = (
                    [("the frame", element)]
                    if element is not None
                    else [(f"the {m.key} response", f) for m, f in every.get(head, [])]
                )
                if not owners:
                    if not self.in_broken_response(head):  # else the response's own mistake is the line to read
                        self.error(at, f"unknown response field {name!r}: no response carries it")
                    continue
                for shown, owner in owners:  # a reply value goes to every response that has the field
                    bits = owner.bits if isinstance(owner, Scalar | FrameElement) else ()  # a List's bits: a flag
                    if bit and bit not in {b.name for b in bits or ()}:
                        self.error(at, f"{shown}'s {head} has no bit field {bit!r}")
                    elif not bit and where == ("reply",) and isinstance(owner, Scalar) and owner.bits:
                        bit_names = [b.name for b in owner.bits]
                        # the simulator builds the value from its bit fields: a whole number is no value of it
                        self.error(
                            at,
                            f"{shown}'s {head} is made of bit fields: give each as `{head}.{bit_names[0]}: ...` "
                            f"(its bit fields: {', '.join(bit_names)})",
                        )
                        break
                    elif isinstance(given, list):
                        problem = list_problem(given, owner)
                        if problem:
                            self.error(at, f"{shown}'s {head}: {problem}")

    def in_broken_response(self, name: str) -> bool:
        """Whether a response declares the field though none resolved carries it: the field (or its response) failed
        to resolve, and that mistake is reported; a reply value for it is no second one."""
        for raw in self.section("commands").values():
            messages = [raw.get("response")] if isinstance(raw, dict) else []
            subcommands = raw.get("subcommands") if isinstance(raw, dict) else None
            if isinstance(subcommands, dict):
                messages += [sub.get("response") for sub in subcommands.values() if isinstance(sub, dict)]
            for response in messages:
                fields = response.get("fields") if isinstance(response, dict) else None
                if isinstance(fields, dict) and name in fields:
                    return True
        return False

    def timeout(
        self, value: Any, path: Path, requests: dict[str, Message], state: dict[str, float]
    ) -> DeviceTimeout | None:
        if value is None:
            return None
        for index, name in enumerate(value["kept_by"]):
            if name not in requests:
                self.error((*path, "kept_by", index), f"unknown command {name!r} (or it has no request)")
        for name in value["sets"]:
            if name not in state:
                self.error((*path, "sets", name), f"unknown state variable {name!r}")
        if value["after"] < 1:
            self.error((*path, "after"), "the timeout must be at least 1 ms")
        return DeviceTimeout(
            int(value["after"]),
            tuple(str(n) for n in value["kept_by"]),
            {str(k): float(v) for k, v in value["sets"].items()},
            str(value.get("description", "")),
        )

    def spaces(self, value: dict[str, Any], path: Path) -> dict[str, Space]:
        found = {}
        for name, item in value.items():
            self.name(name, (*path, name), "data space name")
            if item["size"] < 1:
                self.error((*path, name, "size"), "a data space holds at least one item")
            kind = item["type"]
            found[name] = Space(
                name,
                None if kind == "bit" else SCALARS[kind],
                int(item["size"]),
                str(item.get("access", "rw")),
                str(item.get("description", "")),
            )
        return found

    def errors(self, value: Any, path: Path, commands: list[Command]) -> DeviceErrors | None:
        """`errors:` reason -> reply values, each field checked against the error reply (when there is one)."""
        if value is None:
            return None
        reply = next((m for c in commands for m in c.messages() if m.error_reply), None)
        reasons = {}
        carried = {f.name for f in reply.fields} if reply is not None else set()
        if self.ctx.error_reply is not None and self.ctx.error_reply.status:  # told by its status: it says why
            carried.add(self.ctx.error_reply.status)
        for reason, values in value.items():
            for key in values:
                if reply is not None and key.partition(".")[0] not in carried:
                    self.error((*path, reason, key), f"the error reply {reply.command} has no field {key!r}")
            reasons[str(reason)] = {str(k): float(v) for k, v in values.items()}
        if "unsupported" in reasons:
            if reply is None:
                self.error((*path, "unsupported"), "`unsupported` needs a command whose response is the `error_reply`")
            elif self.ctx.framing is not None and self.ctx.framing.classic:
                self.error(
                    (*path, "unsupported"), "`unsupported` needs frames the frame engine takes apart (not classic)"
                )
        return DeviceErrors(**reasons)

    def space_runs(
        self,
        value: Any,
        names: set[str],
        request: Message,
        spaces: dict[str, Space],
        path: Path,
        response: Message | None = None,
    ) -> dict[str, SpaceAccess]:
        """`reads:`/`writes:` given as field -> run of a data space (a list of names is memory, handled above). A read
        into a single number (a response field that is no array) is one item, without `count`."""
        if not isinstance(value, dict):
            return {}
        request_names = {f.name for f in request.fields}
        runs = {}
        for name, item in value.items():
            item_path = (*path, name)
            if name not in names:
                self.error(item_path, f"{request.command} has no such field {name!r}")
            if item["space"] not in spaces:
                self.error((*item_path, "space"), f"unknown data space {item['space']!r} (not in `spaces:`)")
            for role in ("start", "count"):
                if item.get(role) and item[role] not in request_names:
                    self.error((*item_path, role), f"{request.command} request has no field {item[role]!r}")
            stored = None
            if "value" in item:
                try:
                    stored = expression.parse(item["value"])
                except expression.ExpressionError as exc:
                    self.error((*item_path, "value"), str(exc))
                else:
                    for used in expression.names(stored):
                        if used != "current" and used not in request_names:
                            self.error((*item_path, "value"), f"unknown request field {used!r}")
            read_into = next((f for f in response.fields if f.name == name), None) if response else None
            single = isinstance(read_into, Scalar)
            if single and item.get("count"):
                self.error((*item_path, "count"), f"{name} is one number, not an array: a run read into it is one item")
            runs[str(name)] = SpaceAccess(
                str(item["space"]), str(item["start"]), str(item.get("count", "")), stored, single
            )
        return runs

    def keeps(
        self, value: Any, request_names: Any, entries: Any, path: Path
    ) -> tuple[str, dict[int, tuple[str, ...]]] | None:
        """`keeps`: the request field choosing what a reset keeps, and the entries for each of its values."""
        if value is None:
            return None
        field_name = str(value["field"])
        if field_name not in request_names:
            self.error((*path, "field"), f"no request field {field_name!r}")
        table = {int(k): tuple(str(n) for n in names) for k, names in (value.get("entries") or {}).items()}
        for key, names in table.items():
            for name in names:
                if name not in entries:
                    self.error((*path, "entries", key), f"unknown memory entry {name!r}")
        return field_name, table

    def moving(
        self, value: dict[str, Any], path: Path, entries: dict[str, TableEntry], state: dict[str, float]
    ) -> dict[str, tuple[str, int | None]]:
        """Entries that report whether a state variable is on its way (a whole entry, or one bit of it)."""
        found: dict[str, tuple[str, int | None]] = {}
        for name, item in (value.get("moving") or {}).items():
            where = (*path, "moving", name)
            if name not in entries and name not in state:
                self.error(where, f"unknown memory entry or state variable {name!r}")
            if item["state"] not in entries and item["state"] not in state:
                self.error((*where, "state"), f"unknown state variable {item['state']!r}")
            bit = item.get("bit")
            entry = entries.get(name)
            if bit is not None and entry is not None and not 0 <= bit < entry.type.size * 8:
                self.error((*where, "bit"), f"bit {bit} is outside {name}'s {entry.type.size * 8} bits")
            found[str(name)] = (str(item["state"]), None if bit is None else int(bit))
        return found

    def echoes(
        self,
        item: dict[str, Any],
        path: Path,
        key: str,
        request_names: Container[str],
        response_names: Container[str],
    ) -> tuple[str, ...]:
        """The response fields that repeat the request's field of the same name, each checked to be in both."""
        for index, name in enumerate(item.get("echoes") or ()):
            if name not in response_names or name not in request_names:
                self.error((*path, "echoes", index), f"{key} has no request and response field {name!r}")
        return tuple(str(name) for name in item.get("echoes") or ())

    def behaviour_extras(
        self,
        item: dict[str, Any],
        path: Path,
        key: str,
        request_names: Container[str],
        response_names: Container[str],
        variables: Container[str],
    ) -> dict[str, Any]:
        """The behaviours that stop, wrap, count, hold, release and carry, each name checked."""

        def known(name: str, where: Path) -> str:
            if name not in variables:
                self.error(where, f"unknown state variable {name!r}")
            return name

        counts = {}
        for field_name, count in (item.get("counts") or {}).items():
            if field_name not in response_names:
                self.error((*path, "counts", field_name), f"{key} has no response field {field_name!r}")
            counts[str(field_name)] = (known(str(count["state"]), (*path, "counts", field_name)), float(count["per"]))
        for field_name in item.get("cancel_when") or {}:
            if field_name not in request_names:
                self.error((*path, "cancel_when", field_name), f"{key} has no request field {field_name!r}")
        if "cancel_when" in item and "releases" not in item:
            self.error((*path, "cancel_when"), "`cancel_when` needs `releases`")
        for field_name in item.get("broadcast_ignores") or {}:
            if field_name not in request_names:
                self.error((*path, "broadcast_ignores", field_name), f"{key} has no request field {field_name!r}")
        restores: tuple[str, ...] = ()
        if "restores" in item:
            area, kept = item["restores"]["memory"], item["restores"].get("except") or ()
            for index, name in enumerate(kept):
                known(str(name), (*path, "restores", "except", index))
            if isinstance(variables, Mapping):  # else the unknown kind was reported already
                restores = tuple(
                    name
                    for name, entry in variables.items()
                    if isinstance(entry, TableEntry) and entry.memory == area and name not in kept
                )
        carries = item.get("carries")
        carried: list[str] = []
        if carries:
            for role in ("command", "content"):
                if carries[role] not in request_names:
                    self.error((*path, "carries", role), f"{key} has no request field {carries[role]!r}")
            coded = {c.name for c in self.ctx.commands if c.code is not None and c.request and not c.subcommands}
            for name in carries.get("commands") or ():
                if name not in coded:
                    self.error((*path, "carries", "commands"), f"unknown command {name!r} (or it has no code)")
                carried.append(str(name))
        return {
            "stops": tuple(known(str(n), (*path, "stops")) for n in item.get("stops") or ()),
            "increments": tuple(known(str(n), (*path, "increments")) for n in item.get("increments") or ()),
            "wraps": {known(str(n), (*path, "wraps", n)): float(p) for n, p in (item.get("wraps") or {}).items()},
            "modulo": {known(str(n), (*path, "modulo", n)): float(p) for n, p in (item.get("modulo") or {}).items()},
            "restores": restores,
            "refused_while_moving": (
                known(str(item["refused_while_moving"]), (*path, "refused_while_moving"))
                if "refused_while_moving" in item
                else ""
            ),
            "broadcast_ignores": {str(k): float(v) for k, v in (item.get("broadcast_ignores") or {}).items()},
            "counts": counts,
            "every_device": bool(item.get("every_device", False)),
            "held_while": known(str(item["held_while"]), (*path, "held_while")) if "held_while" in item else "",
            "releases": known(str(item["releases"]), (*path, "releases")) if "releases" in item else "",
            "cancel_when": {str(k): float(v) for k, v in (item.get("cancel_when") or {}).items()},
            "carries": (str(carries["command"]), str(carries["content"])) if carries else None,
            "carried": tuple(carried),
        }

    def models(
        self, value: dict[str, Any], path: Path, entries: dict[str, TableEntry], state: dict[str, float]
    ) -> tuple[DeviceModel, ...]:
        """The device's models, the default first; each value checked against the model's (or the table's) range."""
        model_entry = str(value.get("model_entry", ""))
        if model_entry and model_entry not in entries:
            self.error((*path, "model_entry"), f"unknown memory entry {model_entry!r}")
        models: list[DeviceModel] = []
        numbers: dict[int, str] = {}
        for name, item in (value.get("models") or {}).items():
            model_path = (*path, "models", name)
            self.name(name, model_path, "model name")
            number = int(item["number"])
            if number in numbers:
                self.error((*model_path, "number"), f"model number {number} is already used by {numbers[number]!r}")
            numbers[number] = name
            overrides = []
            for entry_name, override in (item.get("entries") or {}).items():
                entry = entries.get(entry_name)
                if entry is None:
                    self.error((*model_path, "entries", entry_name), f"unknown memory entry {entry_name!r}")
                    continue
                range_path = (*model_path, "entries", entry_name, "range")
                low, high = (
                    self.bounds(entry.type, entry.sign_magnitude, override["range"], range_path, entry.sign_bit)
                    if "range" in override
                    else (entry.minimum, entry.maximum)
                )
                overrides.append(
                    ModelEntry(
                        entry_name,
                        low,
                        high,
                        str(override.get("unit", entry.unit)),
                        override.get("scale", entry.scale),
                        str(override.get("description", "")),
                    )
                )
            by_name = {o.name: o for o in overrides}
            initial = {str(k): float(v) for k, v in (item.get("initial") or {}).items()}
            if model_entry:
                initial[model_entry] = float(number)
            for entry_name, number_value in initial.items():
                entry_path = (*model_path, "initial", entry_name)
                if entry_name in state:
                    continue
                entry = entries.get(entry_name)
                if entry is None:
                    self.error(entry_path, f"unknown memory entry or state variable {entry_name!r}")
                    continue
                bounds = by_name.get(entry_name, entry)
                low, high = bounds.minimum, bounds.maximum
                if not low <= number_value <= high:
                    where = (*model_path, "number") if entry_name == model_entry else entry_path
                    self.error(where, f"{entry_name} = {number_value:g} is outside its range {low:g}..{high:g}")
            models.append(
                DeviceModel(
                    name=name,
                    number=number,
                    title=str(item.get("title", "")),
                    description=str(item.get("description", "")),
                    source=str(item.get("source", "")),
                    initial=initial,
                    entries=tuple(overrides),
                )
            )
        default = value.get("default_model")
        if default is not None:
            found = next((m for m in models if m.name == default), None)
            if found is None:
                known = listed([m.name for m in models])
                self.error((*path, "default_model"), f"unknown model {default!r} (expected one of: {known})")
            else:
                models.remove(found)
                models.insert(0, found)
        return tuple(models)


def reply_value(value: Any) -> Any:
    """A `reply:` value as the model keeps it: text, a number (a float), or a list's items as a tuple (a group's
    items as mappings of its fields)."""
    if isinstance(value, str):
        return value
    if isinstance(value, list):
        return tuple(reply_value(item) for item in value)
    if isinstance(value, dict):
        return {str(k): reply_value(v) for k, v in value.items()}
    return float(value)


def list_problem(items: list[Any], f: Field | FrameElement) -> str:
    """Why `items` cannot be the value of the field `f` in a reply ("" when they can): a list, array or packed
    field takes numbers within its range, a group one mapping of its fields per item; a fixed count must be met."""
    count = getattr(f, "count", None)
    if isinstance(count, int) and len(items) != count:
        return f"{len(items)} items where it holds {count}"
    if isinstance(f, Group):
        names = [g.name for g in f.fields if not (isinstance(g, Scalar) and g.hidden)]
        for index, item in enumerate(items):
            if not isinstance(item, dict):
                return f"item {index} is not a mapping of its fields ({', '.join(names)})"
            unknown = sorted(set(item) - set(names))
            missing = [n for n in names if n not in item]
            if unknown or missing:
                said = [f"no field {', '.join(map(repr, unknown))}"] if unknown else []
                said += [f"no value for {', '.join(map(repr, missing))}"] if missing else []
                return f"item {index}: {'; '.join(said)}"
            for inner in f.fields:
                if isinstance(item.get(inner.name), list):
                    problem = list_problem(item[inner.name], inner)
                    if problem:
                        return f"item {index}'s {inner.name}: {problem}"
        return ""
    if not isinstance(f, List | Array | Packed):
        return "a list for a field that is no list, array or group"
    low, high = (0, 1) if isinstance(f, List) and f.bits else (f.minimum, f.maximum)
    for index, item in enumerate(items):
        if isinstance(item, bool) or not isinstance(item, int | float) or not low <= item <= high:
            return f"item {index} ({item!r}) is not a number in {low:g}..{high:g}"
    return ""
