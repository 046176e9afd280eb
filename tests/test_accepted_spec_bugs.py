"""Specs that `serialspec check` accepts and that a verb then failed on (a traceback or a wrong result), each
written as a new user writes one from docs/language.md (issue 21, "Bugs hit on specs that check accepts")."""

from __future__ import annotations

import importlib
import json
import sys
from pathlib import Path
from types import ModuleType

import pytest
from serialspec.cli import main

HEAD = """\
protocol: {name}
title: A spec a new user writes
byte_order: little
serial:
  baudrate: 9600
"""

# A header, the command, a length and the content: no checksum.
NO_CHECKSUM = """\
framing:
  elements:
    header: {role: header, value: "AA"}
    command: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
commands:
  heartbeat:
    code: 1
    request:
      fields: {kind: u8, mode: u8}
    response:
      fields: {kind: u8, mode: u8}
  status:
    code: 7
    response:
      unsolicited: true
      fields: {level: u8}
"""


def spec(tmp_path: Path, name: str, body: str) -> str:
    path = tmp_path / f"{name}.yaml"
    path.write_text(HEAD.format(name=name) + body)
    return str(path)


def test_a_protocol_without_a_checksum_decodes_and_says_no_checksum_was_checked(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """`decode --json` said "checksum_ok": true where the frames carry no checksum (and the codec of such a
    length-byte framing did not compile: `if whole is not None and :`)."""
    path = spec(tmp_path, "nock", NO_CHECKSUM)
    assert main(["decode", path, "aa 01 02 05 06", "--json", "--direction", "request"]) == 0
    decoded = json.loads(capsys.readouterr().out)
    assert decoded["fields"] == {"kind": 5, "mode": 6}
    assert decoded["checksum_ok"] is None


def test_decode_without_a_direction_takes_the_one_direction_a_frame_decodes_in(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A reply whose code only replies have was refused without --direction ("give the direction")."""
    path = spec(tmp_path, "onlyreply", NO_CHECKSUM)
    assert main(["decode", path, "aa 07 01 05", "--json"]) == 0
    decoded = json.loads(capsys.readouterr().out)
    assert (decoded["direction"], decoded["command"], decoded["fields"]) == ("response", "status", {"level": 5})
    # a frame both directions decode still needs the direction; one that neither does says why
    assert main(["decode", path, "aa 01 02 05 06"]) == 1
    assert "give the direction" in capsys.readouterr().err
    assert main(["decode", path, "aa 09 01 05"]) == 1
    assert capsys.readouterr().err.strip() == "serialspec decode: aa 09 01 05: unknown command 0x09"


# a frame of a header AA, a command, a length, the content and a sum of the command and content
AA_FRAMING = """\
framing:
  elements:
    header: {role: header, value: "AA"}
    command: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [command, content]}
"""


def test_yaml_merge_keys_bring_in_the_anchored_keys(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`<<: *common` gave a traceback (no constructor for tag:yaml.org,2002:merge)."""
    body = (
        AA_FRAMING
        + """\
fields:
  common: &common
    type: u8
    range: [0, 10]
commands:
  one:
    code: 1
    request:
      fields:
        a:
          <<: *common
          description: first
        b: {<<: *common, range: [0, 5]}
"""
    )
    path = spec(tmp_path, "mergek", body)
    assert main(["encode", path, "--json", '{"command": "one", "fields": {"a": 3, "b": 4}}']) == 0
    assert capsys.readouterr().out.strip() == "aa 01 02 03 04 0a"
    assert main(["encode", path, "--json", '{"command": "one", "fields": {"a": 3, "b": 7}}']) == 1
    assert capsys.readouterr().err.strip() == "serialspec encode: one request: b = 7 is outside its range 0..5"


def test_merged_fields_stand_where_the_merge_key_stands(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """`{kind: u8, <<: *tail}` put the merged fields first (PyYAML's order), so `kind` went on the wire after them,
    silently (an EnOcean telegram's data byte after its sender id); a key given beside them that they hold too keeps
    their place, as RTCM 3's `message_number` overriding its station's."""
    body = (
        AA_FRAMING
        + """\
commands:
  one:
    code: 1
    request:
      fields: {kind: u8, <<: &tail {a: u8, b: u8}, c: u8}
  two:
    code: 2
    request:
      fields: {<<: *tail, a: {type: u8, const: 9}}
"""
    )
    path = spec(tmp_path, "mergeo", body)
    assert main(["encode", path, "--json", '{"command": "one", "fields": {"kind": 1, "a": 2, "b": 3, "c": 4}}']) == 0
    assert capsys.readouterr().out.strip() == "aa 01 04 01 02 03 04 0f"
    assert main(["encode", path, "--json", '{"command": "two", "fields": {"b": 3}}']) == 0
    assert capsys.readouterr().out.strip() == "aa 02 02 09 03 10"


def test_encode_a_reply_whose_direction_has_no_address_or_command(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Per-direction `covers`, with the address and command in requests only: encoding a reply failed with "bad
    operand type for unary +: 'bytes'" (the codec wrote `body =  + ...`)."""
    body = """\
framing:
  elements:
    header: {role: header, value: "80"}
    address: {role: address, type: u8, directions: [request]}
    command: {role: command, type: u8, directions: [request]}
    content: {role: content}
    crc:
      role: checksum
      type: u16
      endian: big
      algorithm: crc
      covers: {request: [address, content], response: [content, content]}
      crc: {name: CRC-16/XMODEM, width: 16, poly: 0x1021, init: 0, refin: false, refout: false, xorout: 0,
            check: 0x31C3}
commands:
  read_speed:
    code: 18
    request:
      fields: {}
    response:
      fields: {speed: u32, status: u8}
"""
    path = spec(tmp_path, "perdir", body)
    reply = '{"command": "read_speed", "fields": {"speed": 5, "status": 1}}'
    assert main(["encode", path, "--direction", "response", "--json", reply]) == 0
    assert capsys.readouterr().out.strip() == "80 05 00 00 00 01 33 76"  # CRC-16/XMODEM of 05 00 00 00 01
    assert main(["decode", path, "--direction", "response", "80 05 00 00 00 01 33 76", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["fields"] == {"speed": 5, "status": 1}


def test_docs_of_a_value_element_after_a_content_whose_size_varies(tmp_path: Path) -> None:
    """A status element after the content, whose size differs by command: the reference failed with KeyError
    (the element has no offset from the frame's start)."""
    body = """\
framing:
  elements:
    header: {role: header, value: "B5 62"}
    command: {role: command, type: u8}
    length: {role: length, type: u16}
    content: {role: content}
    status: {role: status, type: u8}
    ck: {role: checksum, type: u16, algorithm: fletcher, covers: [command, status]}
commands:
  short:
    code: 1
    request:
      fields: {a: u8}
  long:
    code: 2
    request:
      fields: {a: u8, b: u32, c: u16}
"""
    path = spec(tmp_path, "mdvalue", body)
    assert main(["generate", path, "--out", str(tmp_path / "out")]) == 0
    docs = (tmp_path / "out" / "docs" / "mdvalue.md").read_text(encoding="utf-8")
    assert "| 3 from the end | status | u8 |" in docs


GROUPS = """\
framing:
  elements:
    header: {role: header, value: "AA"}
    command: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [command, content]}
tables:
  config:
    key: key_id
    entries:
      rate: {key: 1, type: u16}
      mode: {key: 2, type: u8}
      gain: {key: 3, type: i32}
commands:
  set_values:
    code: 1
    request:
      fields:
        count: u8
        items:
          type: group
          count: count
          fields:
            key_id: u16
            value: {type: table_value, table: config, key: key_id}
  names:
    code: 2
    request:
      fields:
        n: u8
        entries:
          type: group
          count: n
          fields:
            id: u8
            name: {type: string, size: 8}
  all_names:
    code: 3
    request:
      fields:
        entries:
          type: group
          count: rest
          fields:
            id: u8
            name: {type: string, size: 4}
"""


@pytest.mark.parametrize(
    ("message", "frame"),
    [
        # a table_value inside a group: NameError _TABLE_CONFIG (the table's structs were made only for values at
        # the top of a message)
        (
            {"command": "set_values", "fields": {"items": [{"key_id": 1, "value": 500}, {"key_id": 3, "value": -2}]}},
            "aa 01 0b 02 01 00 f4 01 03 00 fe ff ff ff 02",
        ),
        # strings of a fixed size in group items: decoded by a struct of the items' numbers alone (IndexError)
        (
            {"command": "names", "fields": {"entries": [{"id": 1, "name": "abcdefgh"}, {"id": 2, "name": "12345678"}]}},
            "aa 02 13 02 01 61 62 63 64 65 66 67 68 02 31 32 33 34 35 36 37 38 e2",
        ),
        (
            {"command": "all_names", "fields": {"entries": [{"id": 7, "name": "left"}, {"id": 8, "name": "righ"}]}},
            "aa 03 0a 07 6c 65 66 74 08 72 69 67 68 71",
        ),
    ],
)
def test_group_items_with_table_values_and_strings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], message: dict[str, object], frame: str
) -> None:
    path = spec(tmp_path, "groups", GROUPS)
    assert main(["encode", path, "--json", json.dumps(message)]) == 0
    assert capsys.readouterr().out.strip() == frame
    assert main(["decode", path, frame, "--json"]) == 0
    fields = json.loads(capsys.readouterr().out)["fields"]
    assert {k: v for k, v in fields.items() if k in ("items", "entries")} == message["fields"]


def generated_package(tmp_path: Path, name: str, body: str) -> ModuleType:
    """The spec generated as a user runs `serialspec generate`, its package imported."""
    path = spec(tmp_path, name, body)
    out = tmp_path / "out"
    assert main(["generate", path, "--out", str(out)]) == 0
    sys.path.insert(0, str(out))
    try:
        return importlib.import_module(name)
    finally:
        sys.path.remove(str(out))


def answers(package: ModuleType, request: object) -> list[object]:
    """The replies the package's simulator (one device, id 0) sends to a request, decoded."""
    simulator = importlib.import_module(f"{package.__name__}.simulator")
    cls = next(v for k, v in vars(simulator).items() if k.endswith("Simulator") and k != "Simulator")
    return [package.decode(frame, "response") for _, frame in cls([0]).feed(package.encode(request))]


SIM_READS = """\
framing:
  elements:
    header: {role: header, value: "AA"}
    command: {role: command, type: u8}
    length: {role: length, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [command, content]}
tables:
  config:
    key: key_id
    entries:
      rate: {key: 1, type: u16, default: 1000}
      mode: {key: 2, type: u8, default: 3}
      gain: {key: 3, type: i32, default: -5}
commands:
  get_values:
    code: 1
    request:
      fields:
        keys: {type: group, count: rest, fields: {key_id: u16}}
    response:
      fields:
        cfg_values:
          type: group
          count: rest
          fields:
            key_id: u16
            value: {type: table_value, table: config, key: key_id}
  read_block:
    code: 2
    request:
      fields: {address: u8, count: u8}
    response:
      fields:
        address: u8
        size: u8
        data: {type: bytes, size: size, table: config, start: address}
device:
  memory: config
  commands:
    get_values:
      reads: [cfg_values]
    read_block:
      reads: [data]
"""


def test_the_simulator_reads_a_group_of_table_values_and_table_bytes_sized_by_a_reply_field(tmp_path: Path) -> None:
    """A device read of a group of table values failed with KeyError: 'cfg_values'; table bytes whose size is an
    earlier reply field (not `size_from` a request field) with KeyError: ''."""
    p = generated_package(tmp_path, "simreads", SIM_READS)
    m = importlib.import_module("simreads.messages")
    (reply,) = answers(p, m.GetValuesRequest(keys=(m.KeysItem(key_id=1), m.KeysItem(key_id=3))))
    assert [(item.key_id, item.value) for item in reply.cfg_values] == [(1, 1000), (3, -5)]
    (reply,) = answers(p, m.ReadBlockRequest(address=1, count=2))
    assert (reply.address, reply.data) == (1, (1000).to_bytes(2, "little"))  # the entry at the start: rate, a u16


SIM_ECHO = """\
framing:
  elements:
    header: {role: header, value: "FD"}
    length: {role: length, type: u8}
    sender: {role: address, type: u8}
    command: {role: command, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: xor, covers: [length, content]}
commands:
  heartbeat:
    code: 0
    request:
      fields:
        kind: {type: u8, description: What the sender is.}
        autopilot: u8
        mode: {type: u8, default: 4}
    response:
      fields:
        kind: {type: u8, description: What the sender is.}
        autopilot: u8
        mode: {type: u8, default: 4}
  set_value:
    code: 1
    request:
      fields: {slot: u8, value: u16}
    response:
      fields: {slot: u8, value: u16}
device:
  reply: {kind: 2}
  state: {autopilot: 3}
  commands:
    set_value:
      echoes: [slot, value]
"""


def test_the_simulator_answers_with_its_own_values_not_the_requests(tmp_path: Path) -> None:
    """A device answered HEARTBEAT with the sender's own values (every request field copied into the reply field
    of the same name): reply fields come from the device (`reply`, its state) or the field's default, and echo
    the request only where the spec says so (`echoes`, the address, the fields replies are matched by)."""
    p = generated_package(tmp_path, "simecho", SIM_ECHO)
    m = importlib.import_module("simecho.messages")
    (reply,) = answers(p, m.HeartbeatRequest(sender=0, kind=6, autopilot=8, mode=1))
    assert (reply.sender, reply.kind, reply.autopilot, reply.mode) == (0, 2, 3, 4)
    (reply,) = answers(p, m.SetValueRequest(sender=0, slot=5, value=700))
    assert (reply.slot, reply.value) == (5, 700)


ONE_RAW_READ = """\
framing:
  elements:
    command: {role: command, type: u8, directions: [request]}
    content: {role: content}
commands:
  read:
    code: 1
    request:
      fields: {length: u8}
    response:
      fields:
        data: {type: bytes, size: rest, size_from: request.length - 2}
"""


def test_the_one_reply_sized_by_its_request_is_read_with_it(tmp_path: Path) -> None:
    """A protocol of one command whose reply is raw bytes as many as the request says (no header, code or length):
    the stream parser took nothing, whatever the request awaited (with a second command it read them), so a client
    timed out. Its bytes are read with the request, whatever the reads."""
    package = generated_package(tmp_path, "raw_read", ONE_RAW_READ)
    request = package.messages.ReadRequest(length=5)
    reply = package.messages.ReadResponse(data=b"abc")
    assert package.encode(reply) == b"abc"
    assert package.decode(b"abc", "response", request=request) == reply
    for sizes in ([3], [1, 1, 1], [2, 1]):
        parser = package.StreamParser("response")
        parser.expect(package.messages.ReadResponse, request)
        stream, found = b"abc", []
        for size in sizes:
            found += parser.feed(stream[:size])
            stream = stream[size:]
        assert found == [reply], sizes
    parser = package.StreamParser("response")
    parser.expect(package.messages.ReadResponse, package.messages.ReadRequest(length=4))
    assert parser.feed(b"ab") == [package.messages.ReadResponse(data=b"ab")]
