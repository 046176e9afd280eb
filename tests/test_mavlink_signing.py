"""MAVLink 2 message signing through `role: optional` + `present_if` (the general optional element), against
pymavlink: frames it signs (a secret key, a link id, a timestamp) decode to its values with the 13 signature bytes
as `signature`, re-encode byte for byte and come out of the stream parser among unsigned ones in any split; a frame
we sign (the signature computed here with hashlib, as the MAVLink guide gives it) passes pymavlink's signature check;
the codec refuses bad signature bytes before a byte is written; and the key's spec mistakes, one line each."""

from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path
from typing import Any

import pytest
from conftest import examples
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import EncodeError
from serialspec.runtime.message import replace

os.environ["MAVLINK20"] = "1"  # before pymavlink is imported: MAVLink 2 frames
mavlink2 = pytest.importorskip("pymavlink.dialects.v20.common")

from serialspec_protocols import mavlink_common as mav  # noqa: E402
from test_mavlink import PAIRS, link, ours, peer_messages, peer_values  # noqa: E402

SETTINGS = settings(max_examples=examples(25), deadline=None, suppress_health_check=list(HealthCheck))
KEY = hashlib.sha256(b"serialspec test passphrase").digest()  # 32 bytes, as pymavlink's setup_signing makes them


def signer(sysid: int, compid: int, seq: int, link_id: int, timestamp: int, key: bytes = KEY) -> Any:
    sender = link(sysid, compid, seq)
    sender.signing.secret_key = key
    sender.signing.link_id = link_id
    sender.signing.timestamp = timestamp
    sender.signing.sign_outgoing = True
    return sender


def signature(frame_before: bytes, link_id: int, timestamp: int, key: bytes = KEY) -> bytes:
    """The 13 signature bytes of a frame (everything before them given): link id, 48-bit timestamp, and the first 6
    bytes of SHA-256(key + frame + link id + timestamp) (mavlink.io/en/guide/message_signing.html)."""
    head = bytes([link_id]) + timestamp.to_bytes(6, "little")
    return head + hashlib.sha256(key + frame_before + head).digest()[:6]


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_frames_pymavlink_signs_decode_and_reencode_byte_for_byte(name: str) -> None:
    _, cls, direction = PAIRS[name]

    @SETTINGS
    @given(
        peer_messages(name),
        st.integers(0, 255),
        st.integers(1, 255),
        st.integers(0, 255),
        st.integers(0, 255),
        st.integers(0, 2**48 - 2),
    )
    def check(message: Any, seq: int, sysid: int, compid: int, link_id: int, timestamp: int) -> None:
        frame = bytes(message.pack(signer(sysid, compid, seq, link_id, timestamp)))
        assert frame[2] == 0x01
        decoded = mav.decode(frame, direction)
        assert type(decoded) is cls
        assert (decoded.seq, decoded.sysid, decoded.compid) == (seq, sysid, compid)
        assert ours(frame, direction) == peer_values(message)
        assert decoded.signature == frame[-13:]
        assert decoded.signature[0] == link_id and int.from_bytes(decoded.signature[1:7], "little") == timestamp
        assert decoded.signature == signature(frame[:-13], link_id, timestamp)  # what a receiver with the key checks
        assert mav.encode(decoded) == frame
        unsigned = mav.encode(replace(decoded, signature=None))
        assert unsigned == bytes(message.pack(link(sysid, compid, seq)))  # pymavlink's frame without signing
        assert mav.decode(unsigned, direction).signature is None

    check()


@pytest.mark.parametrize("name", sorted(PAIRS))
def test_pymavlink_accepts_the_frames_we_sign(name: str) -> None:
    _, cls, direction = PAIRS[name]

    @SETTINGS
    @given(peer_messages(name), st.integers(0, 255), st.integers(1, 255), st.integers(0, 255), st.integers(0, 255))
    def check(message: Any, seq: int, sysid: int, compid: int, link_id: int) -> None:
        timestamp = 1_000_000_000
        values = {**peer_values(message), "seq": seq, "sysid": sysid, "compid": compid}
        unsigned = mav.encode(cls.from_fields(values))
        # the signature covers the frame with its incompat_flags bit set: the frame we send less its 13 bytes
        before = unsigned[:2] + bytes([unsigned[2] | 0x01]) + unsigned[3:-2]
        crc = mavlink2.x25crc(before[1:])
        crc.accumulate(bytes((message.crc_extra,)))
        before += crc.crc.to_bytes(2, "little")
        frame = mav.encode(cls.from_fields({**values, "signature": signature(before, link_id, timestamp).hex()}))
        assert frame[:-13] == before
        receiver = mavlink2.MAVLink(None)
        receiver.signing.secret_key = KEY
        receiver.signing.timestamp = timestamp
        (parsed,) = receiver.parse_buffer(frame)
        assert parsed.get_type() == name and receiver.signing.goodsig_count == 1
        assert peer_values(parsed) == peer_values(message)
        assert bytes(parsed.get_msgbuf()) == frame
        # the same frame under another key: pymavlink refuses its signature (the check above is a real one)
        stranger = mavlink2.MAVLink(None)
        stranger.signing.secret_key = bytes(32)
        stranger.signing.timestamp = timestamp
        with pytest.raises(mavlink2.MAVError, match="Invalid signature"):
            stranger.parse_buffer(frame)
        assert stranger.signing.badsig_count == 1

    check()


def test_the_golden_signed_frame_is_pymavlinks() -> None:
    """The spec's `heartbeat_signed` example, made again by pymavlink with the key, link id and timestamp it names."""
    example = next(e for e in mav_examples() if e.name == "heartbeat_signed")
    sender = signer(1, 1, 17, 3, 123456789, bytes(range(32)))
    assert bytes(mavlink2.MAVLink_heartbeat_message(2, 12, 81, 196608, 3, 3).pack(sender)) == example.frame
    decoded = mav.decode(example.frame, "response")
    assert decoded.signature == bytes.fromhex("03 15 cd 5b 07 00 00 22 be c3 01 6d 66")
    assert signature(example.frame[:-13], 3, 123456789, bytes(range(32))) == decoded.signature


def mav_examples() -> Any:
    return load_protocol(Path(__file__).parents[1] / "specs" / "mavlink_common.yaml").examples


@SETTINGS
@given(
    st.lists(st.tuples(st.booleans(), st.integers(0, 2**32 - 1), st.integers(0, 255)), min_size=1, max_size=6),
    st.lists(st.binary(max_size=5).map(lambda b: b.replace(b"\xfd", b"")), min_size=6, max_size=6),
    st.data(),
)
def test_the_stream_parser_takes_signed_and_unsigned_frames_back_to_back(
    drawn: list[tuple[bool, int, int]], noise: list[bytes], data: st.DataObject
) -> None:
    frames, expected = [], []
    for number, (signed, custom_mode, seq) in enumerate(drawn):
        message = mavlink2.MAVLink_heartbeat_message(2, 12, 81, custom_mode, 3, 3)
        sender = signer(1, 1, seq, number, 1000 + number) if signed else link(1, 1, seq)
        frames.append(bytes(message.pack(sender)))
        expected.append(mav.decode(frames[-1], "response"))
        assert (expected[-1].signature is not None) == signed
    wire = b"".join(noise[i] + frame for i, frame in enumerate(frames)) + noise[-1]
    cuts = sorted(data.draw(st.lists(st.integers(0, len(wire)), max_size=8)))
    pieces = [wire[a:b] for a, b in zip([0, *cuts], [*cuts, len(wire)], strict=True)]
    parser = mav.StreamParser("response")
    assert [m for piece in pieces for m in parser.feed(piece)] == expected
    trickle = mav.StreamParser("response")
    assert [m for byte in wire for m in trickle.feed(bytes([byte]))] == expected


def test_bad_signature_bytes_are_refused_before_a_byte_is_written() -> None:
    beat = mav.HeartbeatResponse(0, 1, 1, 0, 2, 12, 81, 3, 3)
    for wrong, said in (
        (b"\x00" * 12, "signature: 12 bytes, expected 13"),
        ("03 15", "signature must be bytes or None, got str"),
    ):
        with pytest.raises(EncodeError) as refused:
            mav.encode(replace(beat, signature=wrong))
        assert said in str(refused.value) and "\n" not in str(refused.value)
    with pytest.raises(EncodeError, match="signature: 1 bytes, expected 13"):
        mav.encode(mav.HeartbeatResponse.from_fields({**beat.to_fields(), "signature": "03"}))
    assert mav.HeartbeatResponse.from_fields(beat.to_fields()) == beat  # `signature: null` (or left out): unsigned


def test_the_signature_bytes_are_the_frames_last_13() -> None:
    """The codec neither checks nor needs the key: a frame with a wrong signature decodes (checking it is the
    receiver's, with hashlib)."""
    frame = bytearray(mavlink2.MAVLink_heartbeat_message(2, 12, 81, 0, 3, 3).pack(signer(1, 1, 0, 0, 5)))
    frame[-1] ^= 0xFF
    decoded = mav.decode(bytes(frame), "response")
    assert decoded.signature == bytes(frame[-13:])
    assert signature(bytes(frame[:-13]), 0, 5) != decoded.signature


FRAME = """
protocol: optional_case
title: optional elements
byte_order: little
serial: {baudrate: 9600}
framing:
  elements:
    header: {role: header, value: AA}
    flags: {role: constant, value: "00"}
    length: {role: length, type: u8}
    code: {role: command, type: u8}
    content: {role: content}
    checksum: {role: checksum, type: u8, algorithm: sum, covers: [length, content]}
    tag: %s
commands:
  ping: {code: 1, request: {fields: {v: u8}}, response: {}}
"""


@pytest.mark.parametrize(
    ("tag", "said"),
    [
        ('{role: optional, size: 4, present_if: "flags + 1"}', "expected `<element> & <mask>`"),
        ('{role: optional, size: 4, present_if: "nothing & 1"}', "'nothing' is no element before 'tag'"),
        ('{role: optional, size: 4, present_if: "flags & 3"}', "mask 0x3 has more than one bit"),
        ('{role: optional, size: 4, present_if: "flags & 256"}', "mask 0x100 does not fit 'flags'"),
        ('{role: optional, size: 4, present_if: "length & 1"}', "'length' is a length: the flag is a constant"),
        ('{role: optional, size: 4, present_if: "flags & 1", type: u8}', "an optional element is bytes"),
        ('{role: optional, present_if: "flags & 1"}', "an optional element needs `size` and `present_if`"),
        ('{role: optional, size: 0, present_if: "flags & 1"}', "an optional element's size is 1..255 bytes"),
        ('{role: value, present_if: "flags & 1"}', "`present_if` belongs to an optional element"),
    ],
)
def test_present_if_mistakes_are_one_line_each(tmp_path: Path, tag: str, said: str) -> None:
    spec = tmp_path / "optional_case.yaml"
    spec.write_text(FRAME % tag, encoding="utf-8")
    with pytest.raises(SpecErrors) as refused:
        load_protocol(spec)
    lines = str(refused.value).splitlines()
    assert len(lines) == 1 and said in lines[0] and re.match(r".*optional_case\.yaml:\d+:\d+: ", lines[0]), lines


def test_an_optional_element_inside_a_span_is_refused(tmp_path: Path) -> None:
    spec = tmp_path / "optional_case.yaml"
    text = (FRAME % '{role: optional, size: 4, present_if: "flags & 1"}').replace(
        "covers: [length, content]}\n    tag:", "covers: [length, tag]}\n    tag:"
    )
    spec.write_text(text, encoding="utf-8")
    with pytest.raises(SpecErrors) as refused:
        load_protocol(spec)
    assert "lies outside every span" in str(refused.value) or "must come after" in str(refused.value)


def test_the_readme_signature_check_holds_for_a_signed_frame_and_fails_for_a_forged_one() -> None:
    text = (Path(__file__).parents[1] / "README.md").read_text(encoding="utf-8")
    (code,) = [b for b in re.findall(r"```python\n(.*?)```", text, flags=re.S) if "secret_key" in b]
    frame = bytes(mavlink2.MAVLink_heartbeat_message(2, 12, 81, 0, 3, 3).pack(signer(1, 1, 0, 7, 99)))
    exec(code, {"mav": mav, "frame": frame, "secret_key": KEY})
    forged = frame[:-1] + bytes([frame[-1] ^ 1])
    with pytest.raises(AssertionError):
        exec(code, {"mav": mav, "frame": forged, "secret_key": KEY})
