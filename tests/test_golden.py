"""Golden tests: every example frame printed in the documents, and every erratum the specs record.

Each example decodes to the field values the spec records for it, and those values encode back to the same
bytes. Each erratum's check pins which reading of the document is right.
"""

from __future__ import annotations

from contextlib import suppress
from typing import Any

import pytest
from conftest import ALL, Generated, by_protocol, decode, encode, example_class, example_request
from serialspec.checksums.crc import Crc, crc_function
from serialspec.lang.model import Erratum, Example
from serialspec.runtime.errors import DecodeError
from serialspec.runtime.hexbytes import parse_hex

EXAMPLES = by_protocol([(g, e) for g in ALL for e in g.protocol.examples])
ERRATA = by_protocol([(g, e) for g in ALL for e in g.protocol.errata])


def message_class(g: Generated, command: str, subcommand: str | None, direction: str) -> Any:
    for cls in g.package.MESSAGE_TYPES:
        if (cls.COMMAND, cls.SUBCOMMAND, cls.DIRECTION.value) == (command, subcommand, direction):
            return cls
    raise AssertionError(f"no message class for {command} {subcommand} {direction}")


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_example_decodes_to_its_documented_values(g: Generated, example: Example) -> None:
    request = example_request(g, example)  # the request a reply answers, where it is read with it (else None)
    message = decode(g, example.frame, example.direction.value, example_class(g, example), request)
    assert (example.command, example.subcommand) == (message.COMMAND, message.SUBCOMMAND)
    unsent = {e.name for e in g.protocol.framing.layouts[example.direction].optional} - set(example.fields)
    assert message.to_fields() == example.fields | dict.fromkeys(unsent)  # an optional element not recorded: None


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_example_values_encode_to_its_bytes(g: Generated, example: Example) -> None:
    cls = message_class(g, example.command, example.subcommand, example.direction.value)
    assert encode(g, cls.from_fields(example.fields), example_request(g, example)) == example.frame


@pytest.mark.parametrize(("g", "example"), EXAMPLES)
def test_example_printed_bytes_are_the_frame_unless_an_erratum_says_otherwise(g: Generated, example: Example) -> None:
    try:  # hex, or (`printed_as: text`) the frame's characters
        printed = example.printed_text if example.printed_text is not None else parse_hex(example.printed)
    except ValueError:
        printed = None
    if example.erratum:
        assert printed != example.printed_part, f"{example.name} names erratum {example.erratum} but prints it right"
    elif example.completed:
        # no complete frame printed: a placeholder CRC for the check byte, or the values as a table
        assert printed is None and "CRC" in example.printed, f"{example.name} is `completed` but prints a frame"
        with suppress(ValueError):  # a frame printed in hex with the placeholder: all but the check byte as printed
            assert parse_hex(example.printed.replace("CRC", "")) == example.frame[:-1]
    else:
        assert printed == example.printed_part  # the whole frame, or the part the document prints (a Modbus PDU)


@pytest.mark.parametrize(("g", "erratum"), ERRATA)
def test_erratum_is_pinned(g: Generated, erratum: Erratum) -> None:
    check = erratum.check
    direction = check.direction.value if check.direction else None
    if check.kind == "frame_fails":
        with pytest.raises((DecodeError, ValueError)) as failure:
            frame = parse_hex(check.frame_text)
            g.package.decode(frame, direction)
        assert check.error in str(failure.value)
        assert "\n" not in str(failure.value)
    elif check.kind == "frame_decodes_as":
        message = g.package.decode(check.frame, direction)
        assert (check.command, check.subcommand) == (message.COMMAND, message.SUBCOMMAND)
        assert message.to_fields() == check.fields
    elif check.kind == "checksum_value":
        assert check.frame is not None
        assert check.frame[-1] == check.actual != check.claimed
        g.package.decode(check.frame, direction)  # the frame verifies with the actual value
        wrong = check.frame[:-1] + bytes(
            [int(str(check.claimed), 0) if isinstance(check.claimed, str) else check.claimed]
        )
        with pytest.raises(DecodeError, match="checksum"):
            g.package.decode(wrong, direction)
    elif check.kind == "crc_parameters":
        crc = g.protocol.framing.checksum.algorithm
        assert isinstance(crc, Crc) and isinstance(check.claimed, dict)
        claimed = {
            "width": crc.width,
            "poly": crc.poly,
            "init": crc.init,
            "refin": crc.refin,
            "refout": crc.refout,
            "xorout": crc.xorout,
            **check.claimed,
        }
        claimed_crc = crc_function(**claimed)
        layout = g.protocol.framing.layouts
        examples = [e for e in g.protocol.examples if e.name in check.examples] or list(g.protocol.examples)
        assert examples
        for example in examples:
            covered = example.frame[layout[example.direction].covered_from : -1]
            assert claimed_crc(covered) != example.frame[-1], f"{example.name} verifies with the claimed CRC"
            cls = example_class(g, example)
            g.package.decode(example.frame, example.direction.value, cls)  # and with the spec's CRC
    else:
        assert check.kind == "prose"
        assert erratum.printed and erratum.correct and erratum.source


@pytest.mark.parametrize("g", ALL, ids=[g.protocol.name for g in ALL])
def test_every_erratum_appears_in_the_docs(g: Generated) -> None:
    from conftest import ROOT

    docs = (ROOT / "generated" / "docs" / f"{g.protocol.name}.md").read_text(encoding="utf-8")
    for erratum in g.protocol.errata:
        assert erratum.name in docs
