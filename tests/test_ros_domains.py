"""Two suites on one machine never run graphs in the same ROS domain (tests/ros_domains.py).

Two graphs in one domain answer each other's states, and a lockstep run then leaves its
offline episode (docs/design.md section 9, "One graph per domain").
"""

import subprocess
import sys

from ros_domains import SPARES, claim_domain


def test_a_claimed_domain_is_not_given_to_another_process():
    held = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import sys, time; sys.path.insert(0, 'tests'); from ros_domains import "
            "claim_domain; print(claim_domain(224), flush=True); time.sleep(60)",
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert held.stdout.readline().strip() == "224"
        mine = claim_domain(224)
        assert mine != 224 and mine in SPARES
    finally:
        held.kill()
        held.wait()


def test_one_test_asking_twice_gets_the_same_domain_and_two_busy_ones_two_spares():
    # A test passes its domain to several processes (the graph's environment, a
    # --domain-id option, a probe node): each must get the one it claimed first, and two
    # busy preferred domains must not share a spare.
    code = (
        "import sys, time; sys.path.insert(0, 'tests'); from ros_domains import "
        "claim_domain; print(claim_domain(225), claim_domain(226), flush=True); time.sleep(60)"
    )
    held = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert held.stdout.readline().split() == ["225", "226"]
        first, second = claim_domain(225), claim_domain(226)
        assert {first, second} <= set(SPARES) and first != second
        assert claim_domain(225) == first and claim_domain(226) == second
    finally:
        held.kill()
        held.wait()
