"""The `device:` section: how a virtual device behaves, checked against the commands it answers."""

from __future__ import annotations

from collections.abc import Container
from typing import Any

from serialspec.spec.errors import SpecError
from serialspec.spec.loader import Path
from serialspec.spec.model import (
    Behaviour,
    Command,
    Device,
    DeviceKind,
    Direction,
    Field,
    Framing,
    Group,
    Motion,
    Scalar,
    replies_by_request,
    reply_to,
)
from serialspec.spec.passes.base import Pass


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
        if not address:
            self.error(path, "name the field holding the device id with `address:`")
        broadcast = value.get("broadcast", address_element.broadcast if address_element else None)
        id_entry = str(value.get("id_entry", ""))
        if id_entry and id_entry not in entries and id_entry not in (value.get("state") or {}):
            self.error((*path, "id_entry"), f"unknown memory entry or state variable {id_entry!r}")
        state = {str(k): float(v) for k, v in (value.get("state") or {}).items()}
        requests = {m.key: m for c in commands for m in c.messages() if m.direction == Direction.REQUEST}
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
            known_state: Container[str] = (
                kinds[kind_name].state if kind_name in kinds else EVERYTHING if kind_name else state
            )
            response = reply_to(request, replies)
            each = str(item.get("each", ""))
            group = next((f for f in request.fields if isinstance(f, Group) and f.name == each), None)
            if each and group is None:
                self.error((*item_path, "each"), f"{key} has no group field {each!r}")
            item_fields = group.fields if group else ()
            request_names: Container[str] = (
                EVERYTHING if each and group is None else {f.name for f in (*request.fields, *item_fields)} | broken
            )
            response_names = ({f.name for f in response.fields} if response else set()) | broken
            for name in item.get("reads") or ():
                if name not in response_names:
                    self.error((*item_path, "reads"), f"{key} has no response field {name!r}")
            for name in item.get("writes") or ():
                if name not in request_names:
                    self.error((*item_path, "writes"), f"{key} has no request field {name!r}")
            reports = {str(k): str(v) for k, v in (item.get("reports") or {}).items()}
            for field_name, source in reports.items():
                if field_name not in response_names:
                    self.error((*item_path, "reports", field_name), f"{key} has no response field {field_name!r}")
                if source not in known_state and source not in entries:
                    self.error((*item_path, "reports", field_name), f"unknown state variable {source!r}")
            motion = None
            if "moves" in item:
                moves = item["moves"]
                motion = Motion(
                    str(moves["state"]),
                    str(moves["target"]),
                    str(moves.get("duration", "")),
                    str(moves.get("speed", "")),
                )
                if motion.state not in known_state and motion.state not in entries:
                    self.error((*item_path, "moves", "state"), f"unknown state variable {motion.state!r}")
                for role in ("target", "duration", "speed"):
                    name = getattr(motion, role)
                    if name and name not in request_names and name not in entries:
                        self.error((*item_path, "moves", role), f"{key} has no request field or memory entry {name!r}")
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
                    tuple(item.get("reads") or ()),
                    tuple(item.get("writes") or ()),
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
                )
            )
        status = {str(k): str(v) for k, v in (value.get("status") or {}).items()}
        for field_name, entry_name in status.items():
            if entry_name not in entries:
                self.error((*path, "status", field_name), f"unknown memory entry {entry_name!r}")
        return Device(
            description=str(value.get("description", "")),
            memory=memory,
            initial={str(k): float(v) for k, v in (value.get("initial") or {}).items()},
            address=address,
            id_entry=id_entry,
            broadcast=broadcast,
            state=state,
            reply={str(k): float(v) for k, v in (value.get("reply") or {}).items()},
            refused={str(k): float(v) for k, v in (value.get("refused") or {}).items()},
            behaviours=tuple(behaviours),
            status=status,
            kinds=tuple(kinds.values()),
            echo_address=bool(value.get("echo_address", False)),
        )

    def check_ids(self, value: dict[str, Any], path: Path, commands: list[Command], framing: Framing) -> None:
        """`address` (and each kind's) names an integer the requests carry; `reply`, `refused`, `status` name what
        the responses carry."""
        elements = {e.name: e for layout in framing.layouts.values() for e in layout.value_elements}
        carried: dict[Direction, dict[str, Field]] = {Direction.REQUEST: {}, Direction.RESPONSE: {}}
        for command in commands:
            for message in command.messages():
                stack = list(message.fields)
                while stack:
                    f = stack.pop()
                    carried[message.direction].setdefault(f.name, f)
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
        for key in ("reply", "refused", "status"):
            for name in value.get(key) or {}:
                if name not in elements and name not in carried[Direction.RESPONSE]:
                    self.error((*path, key, name), f"unknown response field {name!r}: no response carries it")
