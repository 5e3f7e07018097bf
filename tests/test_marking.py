"""Markings are immutable, hashable values."""

import pytest

from petriflow.errors import MarkingError
from petriflow.marking import Marking, parse_marking


def test_missing_place_holds_zero_tokens():
    """A place the marking does not name holds no token."""
    assert Marking(p=1)["q"] == 0


def test_zero_counts_are_not_stored():
    """Markings that differ only by zero entries are equal and hash alike."""
    assert Marking({"p": 1, "q": 0}) == Marking(p=1)
    assert hash(Marking({"p": 1, "q": 0})) == hash(Marking(p=1))


def test_marking_works_as_dict_key():
    """Equal markings find the same dict entry."""
    seen = {Marking(a=1, b=2): "x"}
    assert seen[Marking(b=2, a=1)] == "x"


@pytest.mark.parametrize("bad", [-1, 1.5, "2", True, None])
def test_bad_token_counts_are_rejected(bad):
    """Negative, fractional, textual and boolean counts raise MarkingError."""
    with pytest.raises(MarkingError):
        Marking({"p": bad})


def test_cover_relation():
    """m >= n holds when m has at least n's tokens everywhere."""
    assert Marking(a=2, b=1) >= Marking(a=1)
    assert not Marking(a=1) >= Marking(a=1, b=1)


def test_parse_marking_rejects_non_object_json():
    """A JSON list is not a marking."""
    with pytest.raises(MarkingError, match="JSON object"):
        parse_marking("[1, 2]")


def test_parse_marking_rejects_unknown_place_with_hint():
    """Unknown places are named with a close match."""
    with pytest.raises(MarkingError, match="did you mean 'ready'"):
        parse_marking('{"redy": 1}', ["ready", "done"])


def test_parse_marking_reports_invalid_json():
    """Broken JSON is a MarkingError, not a traceback from json."""
    with pytest.raises(MarkingError, match="not valid JSON"):
        parse_marking("{p: 1")
