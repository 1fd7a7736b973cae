"""The bounds on what one input may hold, and the variables that raise them."""

import pytest

from evorbc_ros.limits import PRIMITIVES, Limit


def test_a_count_over_the_limit_names_the_variable_and_a_round_value_to_set():
    problem = PRIMITIVES.problem(3_000_017, "in the archive")
    assert problem == (
        "3,000,017 primitives in the archive, more than the limit of 1,000,000; if that is "
        "intended, raise it with EVORBC_MAX_PRIMITIVES=4000000"
    )
    assert PRIMITIVES.problem(1_000_000) is None


def test_the_variable_raises_the_limit_for_a_run(monkeypatch):
    monkeypatch.setenv("EVORBC_MAX_PRIMITIVES", "4_000_000")
    assert PRIMITIVES.value() == 4_000_000 and PRIMITIVES.problem(3_000_017) is None


@pytest.mark.parametrize("raw", ["many", "0", "-5"])
def test_a_bad_variable_is_refused_in_one_line(monkeypatch, raw):
    monkeypatch.setenv("EVORBC_MAX_TEST", raw)
    limit = Limit("things", "EVORBC_MAX_TEST", 10)
    with pytest.raises(ValueError, match="EVORBC_MAX_TEST must be a positive integer"):
        limit.value()
    with pytest.raises(KeyError, match=r"f\.json: EVORBC_MAX_TEST must be"):
        limit.check(1, "f.json", KeyError)
