"""The fuzz corpus through the command line: no hang, no crash, no internal error.

The fast subset runs every named hostile case (big files at a size that still crosses
their limit, or with the limit lowered) and 12 mutants of each format; ``make fuzz`` runs
the whole corpus (big files at full size, 100 mutants a format) and records the table in
docs/fuzz.md.
"""

from __future__ import annotations

import contextlib
import io

import pytest
from fuzz.corpus import make_bases
from fuzz.sweep import corpus, run_cases, table


@pytest.fixture(scope="module")
def outcomes(tmp_path_factory):
    bases = tmp_path_factory.mktemp("bases")
    with contextlib.redirect_stdout(io.StringIO()):
        make_bases(bases)
    cases = corpus(bases, seed=1, per_kind=12, big=False)
    return run_cases(cases, bases, tmp_path_factory.mktemp("cases"), timeout=120.0)


def test_no_case_hangs_crashes_or_ends_in_an_internal_error(outcomes):
    failed = [f"{o.case.name}: {o.outcome}: {o.message[:200]}" for o in outcomes if o.failed]
    assert not failed, "\n".join(failed) + "\n\n" + table(outcomes)


def test_every_named_hostile_case_is_refused_in_one_line_naming_its_file(outcomes):
    named = [o for o in outcomes if o.case.name.startswith("named/")]
    assert len(named) >= 50
    # The named cases whose either outcome is right (a dangling link as a checkpoint is a
    # fresh start) say so with expect None; a few valid but extreme files must be accepted
    # (a wide maze); every other must be refused.
    wrong = [
        f"{o.case.name}: {o.outcome} {o.message}"
        for o in named
        if o.case.expect is not None and o.outcome != o.case.expect
    ]
    assert sum(o.case.expect == "accepted" for o in named) >= 1
    assert not wrong, "\n".join(wrong)


def test_the_mutants_are_both_refused_and_accepted(outcomes):
    # A corpus whose mutants were all refused would test only the first check of each
    # format; one whose mutants were all accepted would test nothing.
    mutants = [o for o in outcomes if o.case.name.startswith("mutant/")]
    kinds = {o.outcome for o in mutants}
    assert len(mutants) == 12 * 10 and {"accepted", "refused"} <= kinds
