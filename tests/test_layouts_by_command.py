"""Layouts chosen by command (`layout:`), bare constant layouts and reply checksums over request bytes
(`from_request`): each mistake in a spec is one line at its place, and the engine's reads of such frames (the
RoboClaw-shaped spec of specs/roboclaw.yaml; tests/test_interop_roboclaw.py checks it against its peer)."""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import pytest
import yaml
from serialspec.lang import SpecErrors, load_protocol

SPEC = Path(__file__).parent.parent / "specs" / "roboclaw.yaml"


def errors_of(tmp_path: Path, change: Any) -> list[str]:
    data = yaml.safe_load(SPEC.read_text(encoding="utf-8"))
    data.pop("examples")
    change(data)
    spec = tmp_path / "rc.yaml"
    spec.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(spec), "rc.yaml")
    return [line.split(": ", 2)[-1] for line in str(failure.value).splitlines()]  # file:line:col: where: what


def unknown_layout(data: dict[str, Any]) -> None:
    data["commands"]["duty_m1"]["layout"] = "writ"


def unknown_direction(data: dict[str, Any]) -> None:
    data["commands"]["duty_m1"]["layout"] = {"request": "write", "reply": "write"}


def fields_in_a_bare_frame(data: dict[str, Any]) -> None:
    data["commands"]["duty_m1"]["response"] = {"fields": {"echo": "i16"}}


def from_request_in_a_request(data: dict[str, Any]) -> None:
    crc = data["framing"]["layouts"]["write"]["elements"]["crc"]
    crc["from_request"] = ["address"]


def from_request_of_no_element(data: dict[str, Any]) -> None:
    crc = data["framing"]["layouts"]["read"]["elements"]["crc"]
    crc["from_request"] = ["address", "sum"]


def from_request_on_a_length(data: dict[str, Any]) -> None:
    elements = data["framing"]["layouts"]["read"]["elements"]
    elements["data"] = copy.deepcopy(elements["data"])
    elements["count"] = {"role": "value", "type": "u8", "from_request": ["address"], "directions": ["request"]}


def one_layout(data: dict[str, Any]) -> None:
    data["framing"] = {"elements": data["framing"]["layouts"]["write"]["elements"]}
    for command in data["commands"].values():
        command.pop("layout")
    data["commands"]["duty_m1"]["layout"] = "write"
    data.pop("device")


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (unknown_layout, "unknown layout 'writ' (the framing has read, write)"),
        (unknown_direction, "expected request or response, not 'reply'"),
        (fields_in_a_bare_frame, "the response frames of layout 'write' have no content, and this response has fields"),
        (from_request_in_a_request, "`from_request` belongs to a checksum of response frames"),
        (
            from_request_of_no_element,
            "'sum' is no element of fixed size of the request frame (it has address, command)",
        ),
        (from_request_on_a_length, "`from_request` belongs to a checksum element"),
        (one_layout, "`layout` chooses one of `framing.layouts`, and the framing has one layout"),
    ],
)
def test_each_mistake_is_one_line(tmp_path: Path, change: Any, expected: str) -> None:
    found = errors_of(tmp_path, change)
    assert expected == found[0] or change is one_layout and expected in found
    assert len(found) == 1 or change is one_layout  # (its replies then share no code: that is said too, earlier)


def test_a_command_without_layout_travels_in_the_first(tmp_path: Path) -> None:
    data = yaml.safe_load(SPEC.read_text(encoding="utf-8"))
    data["commands"]["read_error"].pop("layout")  # `read`, the first layout
    spec = tmp_path / "rc.yaml"
    spec.write_text(yaml.safe_dump(data, sort_keys=False), encoding="utf-8")
    protocol = load_protocol(str(spec), "rc.yaml")
    messages = {m.class_name: m for m in protocol.messages()}
    assert protocol.layout(messages["ReadErrorResponse"]).name == "read"
    assert protocol.layout(messages["DutyM1Response"]).name == "write"
    assert protocol.framing.by_command and protocol.framing.from_request
