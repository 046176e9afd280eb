"""Line-oriented text frames (serialspec.runtime.text) checked against pynmea2, NMEA 0183's peer.

The descriptors below are what generated code will declare from specs/nmea0183.yaml once the spec language has text
framing (issue 22); the field names are pynmea2's, so each decoded value is compared with pynmea2's attribute of the
same name. The golden sentences are pynmea2's test sentences (test/test_types.py) and the NMEA 0183 examples every
receiver manual prints.
"""

from __future__ import annotations

import datetime
import math
import random
from dataclasses import replace
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
    TextField,
    TextFraming,
    TextRepeat,
    TextSentence,
    TextStreamParser,
)


class NorthSouth(Enum):
    north = "N"
    south = "S"


class EastWest(Enum):
    east = "E"
    west = "W"


class Status(Enum):
    valid = "A"
    warning = "V"


def D(name: str, precision: int = 1, **kw: Any) -> TextField:
    return TextField(name, "decimal", precision=precision, **kw)


def I(name: str, width: int = 0, **kw: Any) -> TextField:  # noqa: E743 - one letter per kind, as the table reads
    return TextField(name, "integer", width=width, **kw)


def C(name: str, letters: type[Enum] | None = None) -> TextField:
    return TextField(name, "char", letters=letters)


LATLON = (
    TextField("lat", "angle", precision=4, width=2, minimum=0, maximum=90),
    C("lat_dir", NorthSouth),
    TextField("lon", "angle", precision=4, width=3, minimum=0, maximum=180),
    C("lon_dir", EastWest),
)
TIME = TextField("timestamp", "time", precision=2)

NMEA = TextFraming(
    start="$",
    separator=",",
    end="\r\n",
    checksum=xor_function(8),
    marker="*",
    required=False,
    talker=2,
    talkers=("GP", "GN", "GL", "GA", "BD"),
    sentences=(
        TextSentence(
            "GGA",
            (
                TIME,
                *LATLON,
                I("gps_qual", minimum=0, maximum=8),
                I("num_sats", width=2, minimum=0, maximum=99),
                D("horizontal_dil"),
                D("altitude"),
                C("altitude_units"),
                D("geo_sep"),
                C("geo_sep_units"),
                D("age_gps_data"),
                I("ref_station_id", width=4, minimum=0, maximum=1023),
            ),
        ),
        TextSentence(
            "RMC",
            (
                TIME,
                C("status", Status),
                *LATLON,
                D("spd_over_grnd", minimum=0),
                D("true_course", minimum=0, maximum=360),
                TextField("datestamp", "date"),
                D("mag_variation", minimum=0, maximum=180),
                C("mag_var_dir", EastWest),
                C("mode_indicator"),
            ),
        ),
        TextSentence(
            "VTG",
            (
                D("true_track", minimum=0, maximum=360),
                C("true_track_sym"),
                D("mag_track", minimum=0, maximum=360),
                C("mag_track_sym"),
                D("spd_over_grnd_kts", minimum=0),
                C("spd_over_grnd_kts_sym"),
                D("spd_over_grnd_kmph", minimum=0),
                C("spd_over_grnd_kmph_sym"),
                C("faa_mode"),
            ),
        ),
        TextSentence(
            "GSA",
            (
                C("mode"),
                I("mode_fix_type", minimum=1, maximum=3),
                TextRepeat("sv_ids", (I("sv_id", width=2, minimum=1, maximum=99),), count=12),
                D("pdop"),
                D("hdop"),
                D("vdop"),
            ),
        ),
        TextSentence(
            "GSV",
            (
                I("num_messages", minimum=1, maximum=9),
                I("msg_num", minimum=1, maximum=9),
                I("num_sv_in_view", width=2, minimum=0, maximum=99),
                TextRepeat(
                    "satellites",
                    (
                        I("sv_prn_num", width=2, minimum=1, maximum=999),
                        I("elevation_deg", width=2, minimum=0, maximum=90),
                        I("azimuth", width=3, minimum=0, maximum=359),
                        I("snr", width=2, minimum=0, maximum=99),
                    ),
                    maximum=4,
                ),
            ),
        ),
        TextSentence(
            "GLL",
            (*LATLON, TextField("timestamp", "time"), C("status", Status), C("faa_mode")),
        ),
    ),
)

CHECKED = replace(NMEA, required=True)

GOLDEN = (
    # pynmea2 test/test_types.py
    "$GPGGA,184353.07,1929.045,S,02410.506,E,1,04,2.6,100.00,M,-33.9,M,,0000*6D",
    "$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68",
    "$GPGLL,4916.45,N,12311.12,W,225444,A,*1D",
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
    """Flattened as pynmea2 names them: sv_id01..sv_id12, sv_prn_num_1..4 and so on."""
    flat: dict[str, Any] = {}
    for name, value in sentence.values.items():
        if name == "sv_ids":
            flat.update({f"sv_id{i + 1:02d}": row["sv_id"] for i, row in enumerate(value)})
        elif name == "satellites":
            for i, row in enumerate(value):
                flat.update({f"{key}_{i + 1}": item for key, item in row.items()})
        else:
            flat[name] = value
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
        sign = -1 if ours.values["lat_dir"] is NorthSouth.south else 1
        assert math.isclose(sign * ours.values["lat"].value, theirs.latitude)


@pytest.mark.parametrize("text", GOLDEN)
def test_reencoding_keeps_the_digits_sent(text: str) -> None:
    """0.90 stays 0.90, 000.5 stays 000.5, 184353.07 keeps its hundredths and trailing empty fields stay."""
    assert NMEA.encode_sentence(NMEA.decode(text)) == (text + "\r\n").encode()


def test_decimals_keep_their_digits() -> None:
    decoded = NMEA.decode(NMEA.frame("GPVTG,054.7,T,034.4,M,0.90,N,010.2,K"))
    assert str(decoded.values["spd_over_grnd_kts"]) == "0.90"
    assert b",0.90,N," in NMEA.encode_sentence(decoded)
    floats = dict(decoded.values, spd_over_grnd_kts=0.9)  # a float is written with the declared precision
    assert b",0.9,N," in NMEA.encode("VTG", floats, "GP")


def test_empty_fields_are_none_and_absent_trailing_fields_too() -> None:
    decoded = NMEA.decode("$GPRMC,225446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E*68")
    assert decoded.values["mode_indicator"] is None
    assert decoded.sent == 11
    gsv = NMEA.decode("$GPGSV,3,3,11,22,42,067,42,24,14,311,43,27,05,244,00,,,,*4D")
    assert gsv.values["satellites"][3] == {"sv_prn_num": None, "elevation_deg": None, "azimuth": None, "snr": None}


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*48", "checksum 48 does not match"),
        ("$GPGGA,123519,48x7.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", "GGA: lat = '48x7.038' is not ddmm"),
        ("$GPGGA,123519,4867.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,", "GGA: lat = '4867.038' is not ddmm"),
        ("$GPRMC,225446,X,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E", "RMC: status = 'X' is not one of A, V"),
        ("$GPRMC,256446,A,4916.45,N,12311.12,W,000.5,054.7,191194,020.3,E", "RMC: timestamp = '256446' is not"),
        ("$GPZDA,010203.05,06,07,2008,-08,30", "unknown text code 'ZDA'"),
        ("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K,A,1,2", "VTG: 11 fields, expected at most 9"),
        ("$GPVTG,054.7,T,034.4,M,0x5.5,N,010.2,K", "VTG: spd_over_grnd_kts = '0x5.5' is not a decimal"),
        ("GPVTG,054.7,T,034.4,M,005.5,N,010.2,K", "does not start with '$'"),
        ("$GPVTG,054.7,T*4", "checksum '4' is not 2 hex digits"),
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
        ("GGA", {"num_sats": 100}, "GP", RangeError, "GGA: num_sats = 100 is outside its range 0..99"),
        ("GGA", {"lat": 91.0}, "GP", RangeError, "GGA: lat = 91.0 is outside its range 0..90"),
        ("GGA", {"lat_dir": "E"}, "GP", EncodeError, "GGA: lat_dir must be one of N, S, got 'E'"),
        ("GGA", {"num_sats": 4.0}, "GP", EncodeError, "GGA: num_sats must be an integer, got 4.0"),
        ("GGA", {"altitude": "high"}, "GP", EncodeError, "GGA: altitude must be a number, got 'high'"),
        ("GGA", {"altitude_units": "M,"}, "GP", EncodeError, "GGA: altitude_units must be one character"),
        ("GGA", {"speed": 1}, "GP", EncodeError, "GGA: unknown field 'speed'"),
        ("GGA", {}, "XX", EncodeError, "GGA: talker 'XX' is not one of GP, GN, GL, GA, BD"),
        ("GSV", {"satellites": [{}] * 5}, "GP", RangeError, "GSV: satellites has 5 groups, at most 4"),
        ("GSV", {"satellites": [{"snr": 100}]}, "GP", RangeError, "GSV: satellites[0].snr = 100 is outside"),
        ("RMC", {"datestamp": "191194"}, "GP", EncodeError, "RMC: datestamp must be a datetime.date"),
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

decimals = st.decimals(min_value=0, max_value=999, places=2, allow_nan=False)
times = st.builds(Clock, st.integers(0, 23), st.integers(0, 59), st.integers(0, 59), st.just(0), st.just(0))
angles = st.builds(Angle, st.integers(0, 89), st.decimals(min_value=0, max_value="59.9999", places=4))
fixes = st.fixed_dictionaries(
    {
        "timestamp": times,
        "lat": angles,
        "lat_dir": st.sampled_from(NorthSouth),
        "lon": st.builds(Angle, st.integers(0, 179), st.decimals(min_value=0, max_value="59.9999", places=4)),
        "lon_dir": st.sampled_from(EastWest),
        "gps_qual": st.integers(0, 8),
        "num_sats": st.integers(0, 99),
        "horizontal_dil": st.one_of(st.none(), decimals),
        "altitude": st.floats(-400, 9000).map(lambda x: round(x, 1)),
        "altitude_units": st.just("M"),
        "geo_sep": st.one_of(st.none(), st.decimals(min_value=-99, max_value=99, places=1)),
        "geo_sep_units": st.just("M"),
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
    sign = -1 if values["lat_dir"] is NorthSouth.south else 1
    assert math.isclose(theirs.latitude, sign * values["lat"].value)


@given(
    satellites=st.lists(
        st.fixed_dictionaries(
            {
                "sv_prn_num": st.integers(1, 99),
                "elevation_deg": st.integers(0, 90),
                "azimuth": st.integers(0, 359),
                "snr": st.one_of(st.none(), st.integers(0, 99)),
            }
        ),
        max_size=4,
    )
)
@settings(max_examples=40, deadline=None)
def test_pynmea2_reads_the_satellites_we_send(satellites: list[dict[str, Any]]) -> None:
    values = {"num_messages": 1, "msg_num": 1, "num_sv_in_view": len(satellites), "satellites": satellites}
    frame = NMEA.encode("GSV", values, "GL")
    theirs = pynmea2.parse(frame.decode().strip(), check=True)
    for i, satellite in enumerate(satellites):
        for key, value in satellite.items():
            assert same(value, peer_value(theirs, f"{key}_{i + 1}"))
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
            value = st.text(st.characters(min_codepoint=32, max_codepoint=126, exclude_characters="$,*"), min_size=1)
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
