"""The Python backend's statements (backends/python/ir.py) and the rewrites that make them fast (optimize.py): each
rewrite gives statements that render to the source the codecs rely on, and leaves alone what it must not touch."""

from __future__ import annotations

from serialspec.backends.python.ir import (
    Advance,
    Code,
    If,
    ItemsCheck,
    LeftOver,
    Loop,
    Needs,
    Raise,
    ReturnNew,
    Unpack,
    lines_of,
)
from serialspec.backends.python.optimize import (
    deferred_item_checks,
    field_read,
    fold_last_size_check,
    fuse_unpack,
    read_fields_once,
)

WHERE = "'x request'"


def test_the_last_size_check_folds_into_one_comparison() -> None:
    body = [
        Needs("v_n", f"DecodeError({WHERE} + f': data needs {{v_n}} bytes, {{end - o}} left')"),
        Code("v_data = buf[o : o + v_n]", cursor=True),
        Advance("v_n"),
        LeftOver(WHERE),
        ReturnNew("X", ("v_n", "v_data")),
    ]
    assert lines_of(fold_last_size_check(body)) == [
        "if end - o != v_n:",
        "    if end - o < v_n:",
        f"        raise DecodeError({WHERE} + f': data needs {{v_n}} bytes, {{end - o}} left')",
        f"    raise DecodeError({WHERE} + f': {{end - o - v_n}} bytes left after the last field')",
        "v_data = buf[o : o + v_n]",
        "return _new(X, (v_n, v_data))",
    ]
    moved_elsewhere = [*body[:2], Advance(to="stop + 1"), *body[3:]]
    assert fold_last_size_check(moved_elsewhere) == moved_elsewhere


def test_an_unpack_that_is_the_message_is_returned_as_it_is() -> None:
    body = [Unpack(("v_a", "v_b"), "_S_U8_U16"), ReturnNew("X", ("v_a", "v_b"))]
    assert lines_of(fuse_unpack(body)) == ["return _new(X, _S_U8_U16.unpack_from(buf, o))"]
    reordered = [Unpack(("v_a", "v_b"), "_S_U8_U16"), ReturnNew("X", ("v_b", "v_a"))]
    assert lines_of(fuse_unpack(reordered))[0] == "v_a, v_b = _S_U8_U16.unpack_from(buf, o)"
    byte = [Loop("while o < end", (Unpack(("v_id",), "_S_U8", byte=True), Advance("1")), cursor=True)]
    assert lines_of(fuse_unpack(byte)) == ["while o < end:", "    v_id = buf[o]", "    o += 1"]


def test_fields_read_more_than_once_are_read_once_into_locals() -> None:
    m_id, m_data, item_id = field_read("m", "id"), field_read("m", "data"), field_read("item", "id")
    body = [
        If(f"not 0 <= {m_id} <= 9", (Raise(f"out_of_range({WHERE}, 'id', {m_id}, 0, 9)"),)),
        Loop(f"for item in {m_data}", (Code(f"parts.append({item_id} + {item_id})"),), variable="item"),
        Code(f"return {m_id}"),
    ]
    assert lines_of(read_fields_once(body, ["id", "data"])) == [
        "m_id = m.id",
        "if not 0 <= m_id <= 9:",
        f"    raise out_of_range({WHERE}, 'id', m_id, 0, 9)",
        "for item in m.data:",
        "    item_id = item.id",
        "    parts.append(item_id + item_id)",
        "return m_id",
    ]


def test_a_lists_range_loop_runs_only_when_its_pack_fails() -> None:
    values = field_read("m", "values")
    check = ItemsCheck("x_values", values, "0", "65535", f"out_of_range({WHERE}, 'values', {values}, 0, 65535)", True)
    pack = Code(f"return struct.pack(f'<{{len({values})}}H', *{values})", lists=(values,))
    deferred = lines_of(read_fields_once(deferred_item_checks([check, pack]), ["values"]))
    assert deferred[:6] == [
        "m_values = m.values",
        "try:",
        "    for x_values in m_values:",
        "        if x_values.__class__ is bool:  # struct.pack takes True and False as numbers: refused below",
        "            raise TypeError",
        "    return struct.pack(f'<{len(m_values)}H', *m_values)",
    ]
    assert deferred[-2:] == [
        f"            raise out_of_range({WHERE}, 'values', m_values, 0, 65535) from None",
        "    raise",
    ]
    # a check between the loop and the pack keeps the loop where it was
    between = If("m.id > 9", (Raise("EncodeError('id')"),))
    kept = lines_of(read_fields_once(deferred_item_checks([check, between, pack]), ["values"]))
    assert "try:" not in kept and kept[1] == "for x_values in m_values:"


def test_a_checksum_says_whether_its_call_is_the_codec_function() -> None:
    """The frame code asks the algorithm whether its Python call calls the codec's checksum function (which the codec
    then defines), not the call's text: for each shipped protocol's checksums, the answer is what the call reads."""
    from conftest import ALL
    from serialspec.backends.python.checksum_code import checksum_name

    seen = set()
    for g in ALL:
        for layout in g.protocol.framing.layouts.values():
            for element in layout.elements:
                checksum = element.checksum
                if checksum is None:
                    continue
                name = checksum_name(checksum)
                call = checksum.algorithm.python_call(name)
                assert checksum.algorithm.python_calls_function() == (name in call), (g.protocol.name, call)
                seen.add(checksum.algorithm.python_calls_function())
    assert seen == {True, False}  # both kinds among the shipped protocols (a sum; a CRC)
