"""A one-byte length with a long form (`extended: {when: 0xFF, type: u16}`): the Xsens MT spec's golden frames
(tests/specs/xsens_mt.yaml, the manual's GoToConfig and its acknowledgement, a 255-byte MTData2 in the long form whose
checksum is worked by hand in the spec), the form encode picks at every size, both forms through the stream parser
however the bytes are split, the spec mistakes refused in one line, the C's vectors and the Wireshark dissector.
The language matrix case (tests/test_language_matrix.py, MQTT-SN's shape: the length counting itself, 0x01 then a
u16) runs it through every output with random messages."""

from __future__ import annotations

import contextlib
import datetime
import io
import shutil
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import pytest
from conftest import examples
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.lang import SpecErrors, load_protocol
from serialspec.runtime.errors import DecodeError, EncodeError

SPEC = Path(__file__).parent / "specs" / "xsens_mt.yaml"
MQTT_SN = Path(__file__).parent / "specs" / "mqtt_sn.yaml"


@pytest.fixture(scope="module")
def xsens() -> Iterator[ModuleType]:
    from serialspec.backends.python import files as python_files
    from serialspec.backends.python.memory import imported

    protocol = load_protocol(str(SPEC))
    modules = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    with imported(protocol.name, modules, "the Xsens MT test") as package:
        yield package


def frame(mid: int, data: bytes, long: bool | None = None) -> bytes:
    """An Xsens MT frame built by the manual's rules: FA FF MID LEN [EXT_LEN_HI EXT_LEN_LO] DATA CHECKSUM, the long
    form for 255 bytes and more (or as `long` says), the checksum making the sum of every byte after FA 0."""
    long = len(data) > 254 if long is None else long
    size = bytes([0xFF, len(data) >> 8, len(data) & 0xFF]) if long else bytes([len(data)])
    body = bytes([0xFF, mid]) + size + data
    return b"\xfa" + body + bytes([-sum(body) & 0xFF])


def test_the_manual_s_frames_and_the_long_form_example(xsens: ModuleType) -> None:
    """GoToConfig (FA FF 30 00 D1) and its acknowledgement (FA FF 31 00 D0) as the manual prints them; 255 data bytes
    (one more than LEN holds, LEN itself being the marker) in the long form, its checksum 0x4C worked by hand."""
    assert xsens.encode(xsens.GoToConfigRequest()) == bytes.fromhex("FA FF 30 00 D1")
    assert xsens.encode(xsens.GoToConfigAckResponse()) == bytes.fromhex("FA FF 31 00 D0")
    assert xsens.decode(bytes.fromhex("FA FF 31 00 D0"), "response") == xsens.GoToConfigAckResponse()
    assert xsens.decode(bytes.fromhex("FA FF 01 04 03 88 00 01 70"), "response").device_id == 0x03880001
    long = xsens.encode(xsens.MtData2Response(packets=bytes(range(255))))
    assert long[:6] == bytes.fromhex("FA FF 36 FF 00 FF") and long[-1] == 0x4C and len(long) == 262
    assert sum(long[1:]) & 0xFF == 0  # the manual's rule: every byte after the preamble sums to 0
    assert long == frame(0x36, bytes(range(255)))


@settings(max_examples=examples(25), deadline=None)
@given(
    sizes=st.lists(
        st.one_of(st.integers(0, 2048), st.sampled_from([253, 254, 255, 256, 2048])), min_size=1, max_size=4
    ),
    garbage=st.binary(max_size=4).map(lambda b: b.replace(b"\xfa", b"")),
    data=st.data(),
)
def test_either_form_round_trips_and_streams_however_split(
    xsens: ModuleType, sizes: list[int], garbage: bytes, data: st.DataObject
) -> None:
    """Encode takes the one-byte form up to 254 bytes, the long one from 255 (LEN = FF is the marker); decode
    gives the message back; the stream parser finds every frame, among garbage, in random pieces, as fed a byte at
    a time."""
    messages = [xsens.MtData2Response(packets=bytes([n & 0xFF]) * n) for n in sizes]
    frames = [xsens.encode(m) for m in messages]
    for message, n, sent in zip(messages, sizes, frames, strict=True):
        assert sent == frame(0x36, message.packets)
        assert (sent[3] == 0xFF) == (n > 254)
        assert xsens.decode(sent, "response") == message
    wire = garbage + garbage.join(frames) + garbage
    cuts = sorted(data.draw(st.lists(st.integers(0, len(wire)), max_size=5)))
    parser = xsens.StreamParser("response")
    got = [m for a, b in zip([0, *cuts], [*cuts, len(wire)], strict=True) for m in parser.feed(wire[a:b])]
    trickle = xsens.StreamParser("response")
    assert got == [m for byte in wire for m in trickle.feed(bytes([byte]))] == messages


def test_a_long_form_holding_a_small_value_is_read_and_bad_lengths_are_refused(xsens: ModuleType) -> None:
    """The long form is read whatever it holds (MQTT-SN lets a sender use it for any length; encode still sends the
    one-byte form); a long length outside the range, one that disagrees with the frame and a data too long to send
    are refused in one line."""
    assert xsens.decode(frame(0x36, b"\x01\x02\x03", long=True), "response").packets == b"\x01\x02\x03"
    stream = frame(0x36, b"abc", long=True) + frame(0x36, bytes(300))
    assert [len(m.packets) for m in xsens.StreamParser("response").feed(stream)] == [3, 300]
    too_long = bytes.fromhex("FA FF 36 FF 09 00") + bytes(0x900)
    with pytest.raises(DecodeError, match=r"^len = 2304 is outside its range 0\.\.2048$"):
        xsens.decode(too_long + bytes([-sum(too_long[1:]) & 0xFF]), "response")
    lying = bytearray(frame(0x36, bytes(300)))
    lying[5] += 1
    lying[-1] = -sum(lying[1:-1]) & 0xFF
    with pytest.raises(DecodeError, match=r"^len says 301 but the frame holds 300$"):
        xsens.decode(bytes(lying), "response")
    with pytest.raises(EncodeError, match=r"len = 2049 is outside its range 0\.\.2048$"):
        xsens.encode(xsens.MtData2Response(packets=bytes(2049)))


MID = "    mid: {role: command, type: u8, description: The message identifier.}\n"


@pytest.mark.parametrize(
    ("elements", "said"),
    [
        (
            "    mid: {role: command, type: u8, extended: {when: 0xFF, type: u16}}\n"
            "    len: {role: length, type: u8}\n",
            "`extended` belongs to a length element",
        ),
        (
            MID + "    len: {role: length, type: u16, extended: {when: 0xFF, type: u16}}\n",
            "an extended length is one byte unless it says more: type u8, not u16",
        ),
        (
            MID + "    len: {role: length, type: u8, extended: {when: 0x80, type: u16}}\n",
            "128 lies inside the one-byte form's values 0..255: the marker must be the lowest or highest of them, "
            "or outside them (narrow `range`)",
        ),
        (MID + "    len: {role: length, type: u8, extended: {when: 0xFF}}\n", "missing key 'type'"),
        (
            MID + "    data: {role: content}\n    len: {role: length, type: u8, extended: {when: 0, type: u16}}\n",
            "an extended length comes before the content and any transparency span",
        ),
    ],
)
def test_a_wrong_extended_length_is_one_line(elements: str, said: str, tmp_path: Path) -> None:
    spec = SPEC.read_text(encoding="utf-8")
    start, end = spec.index(MID), spec.index("    data: {role: content}\n")
    if "data:" in elements:
        end += len("    data: {role: content}\n")
    path = tmp_path / "x.yaml"
    path.write_text(spec[:start] + elements + spec[end:], encoding="utf-8")
    with pytest.raises(SpecErrors) as failure:
        load_protocol(str(path), "x.yaml")
    lines = str(failure.value).splitlines()
    assert len(lines) == 1 and lines[0].startswith("x.yaml:") and lines[0].endswith(said), lines


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
@pytest.mark.parametrize(
    ("spec", "printed"), [(SPEC, "xsens_mt: 5"), (MQTT_SN, "mqtt_sn: 3")], ids=["xsens", "mqtt-sn"]
)
def test_the_c_decodes_encodes_and_parses_both_forms(spec: Path, printed: str, tmp_path: Path) -> None:
    """The C's vectors (every example decoded, encoded back byte for byte and found by the parser fed a byte at a
    time): the 255-byte MTData2 is the one-byte form refused by its range (255 is the marker) and sent long; the
    258-byte MQTT-SN PUBLISH is too long for the one-byte form's field."""
    from test_c_backend import check_vectors

    assert check_vectors(spec, spec.stem, tmp_path).strip() == f"{printed} vectors, 0 refused frames, 0 failed"


@pytest.fixture(scope="module")
def mqtt_sn() -> Iterator[ModuleType]:
    from serialspec.backends.python import files as python_files
    from serialspec.backends.python.memory import imported

    protocol = load_protocol(str(MQTT_SN))
    modules = {path.split("/", 1)[1]: code for path, code in python_files(protocol).items()}
    with imported(protocol.name, modules, "the MQTT-SN test") as package:
        yield package


@settings(max_examples=examples(25), deadline=None)
@given(
    size=st.one_of(st.integers(0, 700), st.sampled_from([247, 248, 249, 250])),
    topic_id=st.integers(0, 0xFFFF),
    msg_id=st.integers(0, 0xFFFF),
    byte=st.integers(0, 255),
)
def test_mqtt_sn_publish_as_the_mqttsn_package_writes_and_reads_it(
    mqtt_sn: ModuleType, size: int, topic_id: int, msg_id: int, byte: int
) -> None:
    """PyPI's mqttsn (its Publishes, the length rule of MQTT-SN 1.2 5.2.1 in MessageHeaders) writes our frames byte
    for byte, the one-byte length up to 255 bytes (248 data bytes), 01 and a u16 counting all 3 of its bytes from 256
    on; we read its frames and it reads ours."""
    publishes = pytest.importorskip("mqttsn.lib.publishes")
    message = mqtt_sn.PublishRequest(flags=0x04, topic_id=topic_id, msg_id=msg_id, data=bytes([byte]) * size)
    peer = publishes.Publishes()
    peer.topic_id, peer.msg_id, peer.data = topic_id, msg_id, message.data
    with contextlib.redirect_stdout(io.StringIO()):  # (its pack prints the buffer)
        theirs = peer.pack()
    ours = mqtt_sn.encode(message)
    assert ours == theirs and (ours[0] == 0x01) == (size > 248)
    assert mqtt_sn.decode(theirs, "request") == message
    read = publishes.Publishes(ours)
    assert (read.topic_id, read.msg_id, read.data) == (topic_id, msg_id, message.data)


@pytest.mark.skipif(shutil.which("tshark") is None, reason="tshark is not installed")
def test_tshark_shows_both_forms_as_decode_does(xsens: ModuleType, tmp_path: Path) -> None:
    """The dissector reads either form: frames of 3, 254, 255 and 300 data bytes and a long form holding 3, one a
    packet and all in one packet, each shown as decode --json shows it, its checksum verified."""
    from serialspec import cli
    from serialspec.backends.wireshark.dissector import emit_dissector
    from test_wireshark import TSHARK, decoded, run, shown

    assert TSHARK is not None
    protocol = load_protocol(str(SPEC))
    lua = tmp_path / "xsens_mt.lua"
    lua.write_text(emit_dissector(protocol), encoding="utf-8")
    frames = [frame(0x36, bytes([n & 0xFF]) * n) for n in (3, 254, 255, 300)] + [frame(0x36, b"abc", long=True)]
    moment = datetime.datetime(2026, 11, 25, 10, tzinfo=datetime.UTC)
    lines = ["# serialspec capture: xsens_mt"]
    for data in [*frames, b"".join(frames)]:
        moment += datetime.timedelta(milliseconds=1)
        lines.append(f"{moment.isoformat(timespec='microseconds')} response {data.hex(' ')}")
    capture = tmp_path / "xsens.capture"
    capture.write_text("\n".join(lines) + "\n", encoding="utf-8")
    assert cli.main(["export", str(capture), "--pcap", str(tmp_path / "xsens.pcap")]) == 0
    xml = run(TSHARK, "-X", f"lua_script:{lua}", "-r", str(tmp_path / "xsens.pcap"), "-T", "pdml")
    trees = [
        proto for packet in ET.fromstring(xml).iter("packet") for proto in packet if proto.get("name") == "xsens_mt"
    ]
    wanted = decoded(protocol, "response", frames) * 2
    assert len(trees) == len(wanted) == 10
    for tree, expected in zip(trees, wanted, strict=True):
        seen = shown(protocol, tree)
        assert seen == {key: expected[key] for key in seen} and seen["checksum_ok"], expected["hex"]
