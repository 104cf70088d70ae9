"""``--json`` documents written by :func:`rsstp_cli._json.indented`: the text
``json.dumps(value, indent=2)`` writes, for any JSON value (nested or not, containers of
containers of plain values, keys of every kind json accepts, text with control characters,
brackets and the NUL the encoder separates items with)."""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

from hypothesis import given, settings
from hypothesis import strategies as st

from rsstp_cli._json import indented
from rsstp_cli.replay import main

REFERENCE = Path(__file__).resolve().parents[1] / "recordings" / "thesis-algo-script.mcap"

plain = (
    st.none()
    | st.booleans()
    | st.integers(-(2**70), 2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.text(alphabet=st.characters(codec="utf-8") | st.sampled_from('\0\n"\\,:[]{}'))
)
keys = st.text(max_size=6) | st.integers(-5, 5) | st.floats(width=16) | st.booleans() | st.none()
values = st.recursive(
    plain,
    lambda inner: (
        st.lists(inner, max_size=5)
        | st.lists(inner, max_size=5).map(tuple)
        | st.dictionaries(keys, inner, max_size=5)
    ),
    max_leaves=40,
)
leaves = st.lists(plain, max_size=3) | st.dictionaries(keys, plain, max_size=3)
shallow = (  # containers of containers of plain values (some empty), written in one call
    st.lists(st.lists(plain, max_size=3), min_size=1, max_size=4)
    | st.lists(st.dictionaries(keys, plain, max_size=3), min_size=1, max_size=4)
    | st.dictionaries(keys, st.lists(plain, max_size=3).map(tuple), min_size=1, max_size=4)
    | st.dictionaries(keys, leaves, min_size=1, max_size=4)
)


@settings(max_examples=800, deadline=None)
@given(values | shallow | st.lists(shallow, max_size=3))
def test_the_text_is_json_dumps_with_an_indent_of_two(value: object) -> None:
    assert indented(value) == json.dumps(value, indent=2)


def test_an_audit_document_is_written_as_json_dumps_writes_it() -> None:
    """A real document (the audit of a reference recording, with the truth), read back."""
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        main(["audit", str(REFERENCE), "--truth", "--json", "--quiet"])
    document = json.loads(out.getvalue())
    assert indented(document) == json.dumps(document, indent=2)
    assert out.getvalue() == json.dumps(document, indent=2) + "\n"
