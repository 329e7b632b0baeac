"""rtpy.grading.weeks: a week is ASCII digits of a known week, or one line listing them."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy.grading.weeks import WEEKS, AssignmentError, check_week


@settings(max_examples=150)
@given(
    week=st.one_of(
        st.text(max_size=50),
        st.integers(-10, 20).map(str),
        st.from_regex(r"\A0{0,5}[0-9]{1,2}\Z"),
        st.sampled_from(WEEKS),
    )
)
def test_a_week_is_ascii_digits_of_a_known_week_or_one_line_listing_them(week):
    known = week.isascii() and week.isdigit() and int(week) in {int(w) for w in WEEKS}
    try:
        text = check_week(week)
    except AssignmentError as e:
        assert len(str(e).splitlines()) == 1 and str(e).endswith(", ".join(WEEKS))
        assert not known
        return
    assert known and int(text) == int(week) and text in WEEKS
