"""Text frames (`framing: {kind: text}`, serialspec.runtime.text) checked against pynmea2, NMEA 0183's peer.

The frame and sentences are the package generated from specs/nmea0183.yaml; each decoded value is compared with
pynmea2's attribute for the same field (PEER names them). The golden sentences are pynmea2's test sentences
(test/test_types.py) and the NMEA 0183 examples receiver manuals and gpsd print.
"""

from __future__ import annotations

import contextlib
import datetime
import io
import math
import random
from decimal import Decimal
from enum import Enum
from typing import Any

import pynmea2
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from serialspec.checksums.xor import xor_function
from serialspec.runtime.errors import ChecksumError, DecodeError, EncodeError, RangeError
from serialspec.runtime.text import (
    Angle,
    Clock,
    Fixed,
    Sentence,
    TextCodec,
    TextField,
    TextFraming,
    TextSentence,
    TextStreamParser,
)
from serialspec.runtime.values import replace
from serialspec_protocols import nmea0183

NMEA = nmea0183.FRAMING  # what specs/nmea0183.yaml declares
NorthSouth, EastWest = nmea0183.NorthSouth, nmea0183.EastWest

# Our field names -> pynmea2's attribute names, per sentence; repeats are flattened as pynmea2 names them.
PEER_NAMES = {
    "GGA": "utc timestamp, latitude lat, lat_hemisphere lat_dir, longitude lon, lon_hemisphere lon_dir, quality "
    "gps_qual, satellites num_sats, hdop horizontal_dil, altitude altitude, altitude_unit altitude_units, separation "
    "geo_sep, separation_unit geo_sep_units, dgps_age age_gps_data, dgps_station ref_station_id",
    "RMC": "utc timestamp, status status, latitude lat, lat_hemisphere lat_dir, longitude lon, lon_hemisphere lon_dir, "
    "speed spd_over_grnd, course true_course, date datestamp, variation mag_variation, variation_direction "
    "mag_var_dir, mode mode_indicator",
    "VTG": "course_true true_track, true_reference true_track_sym, course_magnetic mag_track, magnetic_reference "
    "mag_track_sym, speed_knots spd_over_grnd_kts, knots_unit spd_over_grnd_kts_sym, speed_kmh spd_over_grnd_kmph, "
    "kmh_unit spd_over_grnd_kmph_sym, mode faa_mode",
    "GSA": "selection mode, fix mode_fix_type, pdop pdop, hdop hdop, vdop vdop",
    "GSV": "sentences num_messages, sentence msg_num, in_view num_sv_in_view",
}
PEER = {code: dict(pair.split() for pair in names.split(", ")) for code, names in PEER_NAMES.items()}
GROUP_NAMES = {"prn": "sv_prn_num_", "elevation": "elevation_deg_", "azimuth": "azimuth_", "snr": "snr_"}


def test_the_spec_declares_what_the_generated_package_uses() -> None:
    """The frame the tests below run is the generated one: XOR from the checksum registry, the talkers listed."""
    assert (NMEA.start, NMEA.separator, NMEA.marker, NMEA.end, NMEA.talker) == ("$", ",", "*", "\r\n", 2)
    assert NMEA.checksum is not None and NMEA.checksum(b"GPVTG,054.7,T,034.4,M,005.5,N,010.2,K") == 0x48
    assert NMEA.talkers == ("GP", "GN", "GL", "GA", "BD")
    assert [s.code for s in NMEA.sentences] == ["GGA", "RMC", "VTG", "GSA", "GSV"]


CHECKED = replace(NMEA, required=True)

GOLDEN = (
    # pynmea2 test/test_types.py
    "$GPGGA,184353.07,1929.045,S,02410.506,E,1,04,2.6,100.00,M,-33.9,M,,0000*6D",
    "$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68",
    "$GPGSA,A,3,02,,,07,,09,24,26,,,,,1.6,1.6,1.0*3D",
    # NMEA 0183 examples as receiver manuals print them
    "$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47",
    "$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*48",
    "$GPGSV,3,1,11,03,03,111,00,04,15,270,00,06,01,010,00,13,06,292,00*74",
    "$GPGSV,3,3,11,22,42,067,42,24,14,311,43,27,05,244,00,,,,*4D",
    "$GNRMC,001031.00,A,4404.13993,N,12118.86023,W,0.146,,100117,,,A*7B",
)


def peer_value(message: Any, name: str) -> Any:
    value = getattr(message, name)
    return None if value in ("", None) else value


def same(ours: Any, theirs: Any) -> bool:
    """Our decoded value against pynmea2's (which is a string, a number or a time, depending on the field)."""
    if ours is None or theirs is None:
        return ours is None and theirs is None
    match ours:
        case Enum():
            return bool(ours.value == theirs)
        case Angle():
            degrees, minutes = divmod(Decimal(theirs), 100)
            return bool(ours == Angle(int(degrees), minutes)) and str(theirs).endswith(str(ours.minutes))
        case Clock():
            return bool(ours == theirs.replace(tzinfo=None) and isinstance(theirs, datetime.time))
        case bool():
            return False
        case int():
            return ours == int(theirs)
        case Decimal():
            return ours == Decimal(str(theirs))
        case _:
            return bool(ours == theirs)


def values_of(sentence: Sentence) -> dict[str, Any]:
    """Our values under pynmea2's names: used[i].prn as sv_id01..sv_id12, satellites[i].prn as sv_prn_num_1..4."""
    flat: dict[str, Any] = {}
    for name, value in sentence.values.items():
        if name == "used":
            flat.update({f"sv_id{i + 1:02d}": row["prn"] for i, row in enumerate(value)})
        elif isinstance(value, list):
            for i, row in enumerate(value):
                flat.update({f"{GROUP_NAMES[key]}{i + 1}": item for key, item in row.items()})
        else:
            flat[PEER[sentence.code][name]] = value
    return flat


@pytest.mark.parametrize("text", GOLDEN)
def test_decode_gives_pynmea2_values(text: str) -> None:
    theirs = pynmea2.parse(text, check=True)
    ours = NMEA.decode(text)
    assert (ours.talker, ours.code) == (theirs.talker, theirs.sentence_type)
    flat = values_of(ours)
    for name, value in flat.items():
        assert same(value, peer_value(theirs, name)), f"{name}: ours {value!r}, pynmea2 {getattr(theirs, name)!r}"
    if "lat" in flat:
        sign = -1 if ours.values["lat_hemisphere"] is NorthSouth.SOUTH else 1
        assert math.isclose(sign * ours.values["latitude"].value, theirs.latitude)


@pytest.mark.parametrize("text", GOLDEN)
def test_reencoding_keeps_the_digits_sent(text: str) -> None:
    """0.90 stays 0.90, 000.5 stays 000.5, 184353.07 keeps its hundredths and trailing empty fields stay."""
    assert NMEA.encode_sentence(NMEA.decode(text)) == (text + "\r\n").encode()


def test_decimals_keep_their_digits() -> None:
    decoded = NMEA.decode(NMEA.frame("GPVTG,054.7,T,034.4,M,0.90,N,010.2,K"))
    assert str(decoded.values["speed_knots"]) == "0.90"
    assert b",0.90,N," in NMEA.encode_sentence(decoded)
    floats = dict(decoded.values, speed_knots=0.9)  # a float is written with the declared precision
    assert b",0.9,N," in NMEA.encode("VTG", floats, "GP")


def test_empty_fields_are_none_and_absent_trailing_fields_too() -> None:
    decoded = NMEA.decode("$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68")
    assert decoded.values["mode"] is None
    assert decoded.sent == 11
    gsv = NMEA.decode("$GPGSV,3,3,11,22,42,067,42,24,14,311,43,27,05,244,00,,,,*4D")
    assert gsv.values["satellites"][3] == {"prn": None, "elevation": None, "azimuth": None, "snr": None}


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48", "bad checksum: the frame has 48"),
        ("$GPGGA,123519,48x7.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", "GGA: latitude = '48x7.038' is not ddmm"),
        ("$GPGGA,123519,4867.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", "GGA: latitude = '4867.038' is not ddmm"),
        ("$GPRMC,225446,X,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E", "RMC: status = 'X' is not one of A, V"),
        ("$GPRMC,256446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E", "RMC: utc = '256446' is not"),
        ("$GPZDA,010203.05,06,07,2008,-08,30", "unknown text code 'ZDA'"),
        ("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K,A,1,2", "VTG: 11 fields, expected at most 9"),
        ("$GPVTG,054.7,T,034.4,M,0x5.5,N,010.2,K", "VTG: speed_knots = '0x5.5' is not a decimal"),
        ("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K", "does not start with '$'"),
        ("$GPVTG,054.7,T*4", "checksum '4' is not 2 hex digits"),
        # a terminal's LF where the spec says CR LF: the error names the protocol's line ending
        ("$GPVTG,054.7,T*4A\n", "is not 2 hex digits (a line ending? this protocol's lines end with '\\r\\n'"),
    ],
)
def test_bad_frames_get_one_line_reasons(text: str, reason: str) -> None:
    with pytest.raises(DecodeError) as error:
        NMEA.decode(text)
    assert reason in str(error.value)
    assert "\n" not in str(error.value)


def test_checksum_errors_are_checksum_errors() -> None:
    with pytest.raises(ChecksumError):
        NMEA.decode("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*49")
    required = TextFraming("$", ",", "\r\n", NMEA.sentences, checksum=xor_function(8), talker=2)
    with pytest.raises(ChecksumError, match="no checksum"):
        required.decode("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K")


@pytest.mark.parametrize(
    ("code", "values", "talker", "error", "reason"),
    [
        ("GGA", {"satellites": 100}, "GP", RangeError, "GGA: satellites = 100 is outside its range 0..99"),
        ("GGA", {"latitude": 91.0}, "GP", RangeError, "GGA: latitude = 91.0 is outside its range 0..90"),
        ("GGA", {"lat_hemisphere": "E"}, "GP", EncodeError, "GGA: lat_hemisphere must be one of 'N', 'S', got 'E'"),
        ("GGA", {"satellites": 4.0}, "GP", EncodeError, "GGA: satellites must be an integer, got 4.0"),
        ("GGA", {"altitude": "high"}, "GP", EncodeError, "GGA: altitude must be a number, got 'high'"),
        ("GGA", {"altitude_unit": "M,"}, "GP", EncodeError, "GGA: altitude_unit must be one of 'M', got 'M,'"),
        ("GGA", {"speed": 1}, "GP", EncodeError, "GGA: unknown field 'speed'"),
        ("GGA", {}, "XX", EncodeError, "GGA: talker 'XX' is not one of GP, GN, GL, GA, BD"),
        ("GSV", {"satellites": [{}] * 5}, "GP", RangeError, "GSV: satellites has 5 groups, at most 4"),
        ("GSV", {"satellites": [{"snr": 100}]}, "GP", RangeError, "GSV: satellites[0].snr = 100 is outside"),
        ("RMC", {"date": "191194"}, "GP", EncodeError, "RMC: date must be a datetime.date"),
        ("ZDA", {}, "GP", EncodeError, "unknown text code 'ZDA'"),
    ],
)
def test_bad_values_are_refused_naming_the_field(
    code: str, values: dict[str, Any], talker: str, error: type[Exception], reason: str
) -> None:
    with pytest.raises(error) as raised:
        NMEA.encode(code, values, talker)
    assert reason in str(raised.value)


def test_text_fields_cannot_carry_frame_characters() -> None:
    frame = TextFraming("$", ",", "\r\n", (TextSentence("TXT", (TextField("text", "text"),)),), talker=2)
    assert frame.decode(frame.encode("TXT", {"text": "ROM BASE 2.01"}, "GN")).values == {"text": "ROM BASE 2.01"}
    with pytest.raises(EncodeError, match=r"TXT: text: 'a,b' holds ','"):
        frame.encode("TXT", {"text": "a,b"}, "GN")


# --- what we send, pynmea2 reads -------------------------------------------------------------------------------

decimals = st.decimals(min_value=0, max_value=99, places=1, allow_nan=False)
times = st.builds(Clock, st.integers(0, 23), st.integers(0, 59), st.integers(0, 59), st.just(0), st.just(0))
angles = st.builds(Angle, st.integers(0, 89), st.decimals(min_value=0, max_value="59.9999", places=4))
fixes = st.fixed_dictionaries(
    {
        "utc": times,
        "latitude": angles,
        "lat_hemisphere": st.sampled_from(NorthSouth),
        "longitude": st.builds(Angle, st.integers(0, 179), st.decimals(min_value=0, max_value="59.9999", places=4)),
        "lon_hemisphere": st.sampled_from(EastWest),
        "quality": st.integers(0, 8),
        "satellites": st.integers(0, 99),
        "hdop": st.one_of(st.none(), decimals),
        "altitude": st.floats(-400, 9000).map(lambda x: round(x, 1)),
        "altitude_unit": st.just("M"),
        "separation": st.one_of(st.none(), st.decimals(min_value=-99, max_value=99, places=1)),
        "separation_unit": st.just("M"),
    }
)


@given(values=fixes, talker=st.sampled_from(NMEA.talkers))
@settings(max_examples=60, deadline=None)
def test_pynmea2_parses_every_fix_we_encode(values: dict[str, Any], talker: str) -> None:
    frame = NMEA.encode("GGA", values, talker)
    theirs = pynmea2.parse(frame.decode().strip(), check=True)
    ours = NMEA.decode(frame)
    assert theirs.talker == talker
    for name, value in values_of(ours).items():
        assert same(value, peer_value(theirs, name)), name
    sign = -1 if values["lat_hemisphere"] is NorthSouth.SOUTH else 1
    assert math.isclose(theirs.latitude, sign * values["latitude"].value)


@given(
    satellites=st.lists(
        st.fixed_dictionaries(
            {
                "prn": st.integers(1, 99),
                "elevation": st.integers(0, 90),
                "azimuth": st.integers(0, 359),
                "snr": st.one_of(st.none(), st.integers(0, 99)),
            }
        ),
        max_size=4,
    )
)
@settings(max_examples=40, deadline=None)
def test_pynmea2_reads_the_satellites_we_send(satellites: list[dict[str, Any]]) -> None:
    values = {"sentences": 1, "sentence": 1, "in_view": len(satellites), "satellites": satellites}
    frame = NMEA.encode("GSV", values, "GL")
    theirs = pynmea2.parse(frame.decode().strip(), check=True)
    for i, satellite in enumerate(satellites):
        for key, value in satellite.items():
            assert same(value, peer_value(theirs, f"{GROUP_NAMES[key]}{i + 1}"))
    assert NMEA.decode(frame).values == values


# --- the stream parser ------------------------------------------------------------------------------------------


def noisy_stream(rng: random.Random) -> tuple[bytes, list[Sentence], int]:
    """Golden sentences with noise between them (never a '$') and a few broken ones; what a parser must find."""
    stream, expected, broken = b"", [], 0
    for _ in range(30):
        noise = bytes(rng.choice(b"abc\r\n,*\x00\xff 0123456789") for _ in range(rng.randrange(0, 12)))
        text = rng.choice(GOLDEN)
        frame = (text + "\r\n").encode()
        match rng.randrange(6):
            case 0:  # a corrupt checksum
                frame = frame[:-4] + (b"1" if frame[-4:-3] == b"0" else b"0") + frame[-3:]
                broken += 1
            case 1:  # cut short: the next frame starts before this one ends
                frame = frame[: rng.randrange(1, len(frame) - 2)]
                broken += 1
            case _:
                expected.append(NMEA.decode(text))
        stream += noise + frame
    return stream, expected, broken


@given(seed=st.integers(0, 2**32 - 1), pieces=st.lists(st.integers(1, 40), min_size=1, max_size=50))
@settings(max_examples=60, deadline=None)
def test_stream_finds_every_sentence_in_noise_and_random_pieces(seed: int, pieces: list[int]) -> None:
    stream, expected, broken = noisy_stream(random.Random(seed))
    stream += b"$"  # the last cut-short frame, if any, is found cut short by this start
    parser = TextStreamParser(CHECKED)  # a frame cut short could be a valid frame without its checksum
    found: list[Sentence] = []
    at, turn = 0, 0
    while at < len(stream):
        size = pieces[turn % len(pieces)]
        found += parser.feed(stream[at : at + size])
        at, turn = at + size, turn + 1
    assert found == expected
    assert parser.corrupt == broken
    assert parser.pending() == b"$"


def test_stream_drops_a_line_that_never_ends() -> None:
    parser = TextStreamParser(NMEA)
    assert parser.feed(b"$GPGGA," + b"1" * 200) == []
    assert parser.corrupt == 1
    assert "no line ending within 82 characters" in parser.last_error
    assert parser.feed(b"\r\n" + GOLDEN[5].encode() + b"\r\n") == [NMEA.decode(GOLDEN[5])]


# --- every kind, both ways ----------------------------------------------------------------------------------------


def field_values(spec: TextField) -> st.SearchStrategy[Any]:
    """Values of one field as a device would send them (None: an empty field)."""
    low = 0 if spec.minimum is None else int(spec.minimum)
    high = 9999 if spec.maximum is None else int(spec.maximum)
    match spec.kind:
        case "decimal":
            value: st.SearchStrategy[Any] = st.decimals(min_value=low, max_value=high, places=3).map(
                lambda d: Fixed(format(d, "f"))
            )
        case "integer":
            value = st.integers(low, high)
        case "angle":
            value = st.builds(Angle, st.integers(low, high - 1), st.decimals(min_value=0, max_value="59.99", places=2))
        case "char" if spec.letters is not None:
            value = st.sampled_from(spec.letters)
        case "char":
            value = st.sampled_from("ABKMNTV")
        case "text":
            value = st.text(st.characters(min_codepoint=32, max_codepoint=126, exclude_characters="$,*#;!"), min_size=1)
        case "time":
            value = st.builds(Clock, st.integers(0, 23), st.integers(0, 59), st.integers(0, 59), st.just(0))
        case "date":
            value = st.dates(datetime.date(1969, 1, 1), datetime.date(2068, 12, 31))
    return st.one_of(st.none(), value)


def sentence_values(sentence: TextSentence) -> st.SearchStrategy[dict[str, Any]]:
    fields: dict[str, st.SearchStrategy[Any]] = {}
    for item in sentence.fields:
        if isinstance(item, TextField):
            fields[item.name] = field_values(item)
        else:
            row = st.fixed_dictionaries({f.name: field_values(f) for f in item.fields})
            size = item.count or item.maximum
            fields[item.name] = st.lists(row, min_size=item.count, max_size=size)
    return st.fixed_dictionaries(fields)


@given(data=st.data(), sentence=st.sampled_from(NMEA.sentences), talker=st.sampled_from(NMEA.talkers))
@settings(max_examples=200, deadline=None)
def test_every_sentence_decodes_to_what_was_encoded(data: st.DataObject, sentence: TextSentence, talker: str) -> None:
    values = data.draw(sentence_values(sentence))
    frame = NMEA.encode(sentence.code, values, talker)
    decoded = NMEA.decode(frame)
    assert (decoded.talker, decoded.code, decoded.values) == (talker, sentence.code, values)
    assert NMEA.encode_sentence(decoded) == frame
    assert pynmea2.parse(frame.decode().strip(), check=True).sentence_type == sentence.code


# --- the generated package ----------------------------------------------------------------------------------------


def test_generated_messages_decode_encode_and_stream() -> None:
    text = "$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68"
    message = nmea0183.decode(text)
    assert isinstance(message, nmea0183.RmcResponse)
    assert (message.talker, message.status, message.speed) == ("GP", nmea0183.Status.VALID, Decimal("0.5"))
    assert message.date == datetime.date(1994, 11, 19) and message.mode is None
    assert nmea0183.encode(message) == (text + "\r\n").encode()
    built = nmea0183.GsvResponse(
        talker="GL",
        sentences=1,
        sentence=1,
        in_view=1,
        satellites=(nmea0183.GsvResponseSatellites(prn=65, elevation=40, azimuth=112, snr=None),),
    )
    frame = nmea0183.encode(built)
    assert pynmea2.parse(frame.decode().strip(), check=True).sv_prn_num_1 == "65"
    parser = nmea0183.StreamParser()
    found = [m for byte in b"noise" + frame + (text + "\r\n").encode() for m in parser.feed(bytes([byte]))]
    assert found == [built, message]
    with pytest.raises(RangeError, match="GGA: satellites = 120 is outside its range 0..99"):
        nmea0183.encode(nmea0183.GgaResponse(satellites=120))
    assert isinstance(nmea0183.CODEC, TextCodec)


# --- spec mistakes --------------------------------------------------------------------------------------------------

TINY_TEXT = """\
protocol: tiny_text
title: Tiny
serial: {baudrate: 9600}
framing:
  kind: text
  start: "$"
  separator: ","
  checksum: {algorithm: xor}
  end: "\\r\\n"
  talker: {size: 2, values: [GP]}
commands:
  fix:
    code: FIX
    response:
      fields:
        lat: {type: angle, width: 2, precision: 4}
        ns: {type: char, letters: {north: N, south: S}}
        sats: {type: repeat, max_count: 4, fields: {prn: integer}}
"""


@pytest.mark.parametrize(
    ("change", "expected"),
    [
        (("kind: text", "kind: text\n  gap: 3.5"), "framing.gap: `gap` belongs to binary framing, not `kind: text`"),
        (('  start: "$"\n', '  start: "$$"\n'), "framing: `start` (when given) and `separator` must be one character"),
        (('  separator: ","\n', ""), "framing: missing key 'separator'"),
        (("values: [GP]", "values: [GPS]"), "framing.talker.values[0]: talker 'GPS' is not 2 characters"),
        (("algorithm: xor", "algorithm: crc"), "framing.checksum.algorithm: unknown value 'crc'"),
        (("code: FIX", "code: 7"), "commands.fix.code: a text command needs a text `code`"),
        (("type: angle,", "type: angel,"), "commands.fix.response.fields.lat: unknown text field type 'angel'"),
        (("width: 2, precision: 4", "width: 2, letters: {a: A}"), "lat.letters: `letters` does not apply to a angle"),
        (("north: N", "north: NX"), "fields.ns.letters.north: 'NX' is not one letter"),
        (("prn: integer}}", "prn: integer}}\n        last: text"), "sats: a repeat with `max_count` must be the last"),
        (("max_count: 4", "max_count: 4, count: 2"), "sats: a repeat needs `count` (always sent) or `max_count`"),
        (("commands:", "enums: {e: {values: {a: 1}}}\ncommands:"), "enums: `enums` is not available in text frames"),
        (
            ("    response:\n", "    response:\n      text: {start: A, separator: '|'}\n"),
            "text.start: a message's text",
        ),
        (
            ("    response:\n", "    response:\n      text: {start: <, separator: '||'}\n"),
            "text.separator: `separator` is one",
        ),
        (
            ("    response:\n", "    response:\n      text: {start: <, separator: '*'}\n"),
            "text: `separator`, `named` and",
        ),
        (("    response:\n", "    response:\n      text: {start: <, separator: '|', named: ':'}\n"), "needs a `label`"),
        (
            ("    response:\n", "    response:\n      text: {start: <, separator: '|', named: ':'}\n"),
            "a labelled repeat needs `text.list`",
        ),
        (("lat: {type: angle,", "lat: {label: LAT, type: angle,"), "lat.label: a label needs `text: {named: ...}`"),
    ],
)
def test_text_spec_mistakes_are_one_line_each(change: tuple[str, str], expected: str) -> None:
    from serialspec.lang import SpecErrors
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    assert resolve(load_text(TINY_TEXT, "tiny.yaml")).text is not None
    with pytest.raises(SpecErrors) as error:
        resolve(load_text(TINY_TEXT.replace(*change), "tiny.yaml"))
    lines = str(error.value).splitlines()
    assert any(expected in line and line.startswith("tiny.yaml:") for line in lines), lines


@pytest.mark.parametrize(
    ("spec", "change", "expected"),
    [
        (
            "modbus_rtu",
            ("type: u16, range: [1, 2000]", "type: u16, precision: 2"),
            "`precision` belongs to fields of text",
        ),
        ("modbus_rtu", ("  gap: 3.5", "  gap: 3.5\n  separator: ','"), "`separator` belongs to text frames"),
        ("modbus_rtu", ("code: 0x01", "code: RC"), "expected an integer, got text"),
    ],
)
def test_text_keys_in_a_binary_spec_are_refused(spec: str, change: tuple[str, str], expected: str) -> None:
    from conftest import ROOT
    from serialspec.lang import SpecErrors
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    text = (ROOT / "specs" / f"{spec}.yaml").read_text(encoding="utf-8")
    assert change[0] in text
    with pytest.raises(SpecErrors) as error:
        resolve(load_text(text.replace(*change, 1), f"{spec}.yaml"))
    assert expected in str(error.value)


def test_an_example_that_does_not_decode_as_recorded_is_a_spec_error() -> None:
    from conftest import ROOT
    from serialspec.backends.python import EMITTER
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    text = (ROOT / "specs" / "nmea0183.yaml").read_text(encoding="utf-8").replace('hdop: "0.9"', 'hdop: "0.90"')
    protocol = resolve(load_text(text, "nmea0183.yaml"))
    assert EMITTER.verify is not None
    problems = EMITTER.verify(protocol, EMITTER.files(protocol))
    assert [p.message for p in problems] == ["the frame decodes to other values: hdop is '0.9', not '0.90'"]


def test_the_tutorial_text_session_prints_what_it_says() -> None:
    from conftest import ROOT

    page = (ROOT / "docs" / "tutorial.md").read_text(encoding="utf-8")
    first = "from serialspec_protocols import nmea0183\n"
    session = page.split("```python\n" + first, 1)[1].split("```", 1)[0]
    code = first + session
    printed = [line.removeprefix("# ") for line in session.splitlines() if line.startswith("# ")]
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        exec(compile(code, "tutorial.md", "exec"), {})
    assert out.getvalue().splitlines() == printed


@pytest.mark.parametrize("verb", [["scan", "--port", "/dev/null"]])
def test_verbs_that_address_devices_by_id_refuse_a_text_protocol_in_one_line(verb: list[str]) -> None:
    import subprocess
    import sys

    from conftest import ROOT

    spec = str(ROOT / "specs" / "nmea0183.yaml")
    result = subprocess.run(
        [sys.executable, "-m", "serialspec", verb[0], spec, *verb[1:]], capture_output=True, text=True, check=False
    )
    assert result.returncode != 0
    assert result.stderr.count("\n") == 1 and "is a text protocol" in result.stderr, result.stderr


def test_a_field_refused_is_not_refused_again_where_the_device_names_it() -> None:
    """One mistake, one line: a response field of an unknown type is refused where it is declared, not again as "has
    no field" where the device reports it; what the device reports it from is still checked (a second mistake, its
    own line)."""
    from serialspec.lang import SpecErrors
    from serialspec.lang.loader import load_text
    from serialspec.lang.resolve import resolve

    spec = """
protocol: psu
title: Bench supply
serial: {baudrate: 9600}
framing: {kind: text, end: "\\r\\n", separator: " "}
commands:
  voltage:
    code: "VOLT?"
    request: {}
    response: {fields: {volts: {type: float}}}
  set_voltage:
    code: VOLT
    request: {fields: {volts: {type: decimal, precision: 2, range: [0, 30]}}}
device:
  state: {volts: 5}
  commands:
    set_voltage: {stores: {volts: volts}}
    voltage: {reports: {volts: volt}}
"""
    with pytest.raises(SpecErrors) as error:
        resolve(load_text(spec, "psu.yaml"))
    lines = str(error.value).splitlines()
    assert len(lines) == 2, lines
    assert "commands.voltage.response.fields.volts: unknown text field type 'float'" in lines[0]
    assert "device.commands.voltage.reports.volts: unknown name 'volt' (not a state variable)" in lines[1]
