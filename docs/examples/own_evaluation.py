"""A repertoire for a robot of your own, evaluated by your own code (evorbc as a library).

The robot is a unicycle: a primitive holds a forward speed v (m/s) and a turn rate w
(rad/s) for T = 2 s from rest. Its motion has a closed form, an arc: after t seconds it
has turned w t and its chord, of length v t sin(w t / 2) / (w t / 2), points at w t / 2.
MAP-Elites asks for genes, this script evaluates them and tells the results back; the
quality is the paper's "distance" metric (straight-line displacement over path length),
so in each cell of the archive the straightest way there wins.

Then an arbitrator uses the repertoire as the onboard one does: every 0.1 s, two numbers
in [0, 1] (here from a hand-written rule instead of an evolved network) go through the
polar mapping onto the behaviour space, and the primitive nearest that point runs for
the next 0.1 s, until the unicycle reaches a goal.

Run: ``python docs/examples/own_evaluation.py --out unicycle.json [--plot unicycle.png]``.
See docs/design.md section 20 for the library API.
"""

from __future__ import annotations

import argparse
import math

import numpy as np

from evorbc_ros import MappingFunction, ParameterSpec, PrimitiveLookup, Repertoire
from evorbc_ros import choose_primitive as choose
from evorbc_ros.repertoire import declare_robot
from offline_evolution import MapElites, MapElitesSettings, quality_metric
from sim_bridge import PrimitiveOutcome

#: The unicycle's locomotion parameters: gene -1 is ``low``, gene 1 is ``high``.
PARAMETERS = (
    ParameterSpec("speed", "m/s", -0.3, 0.3),
    ParameterSpec("turn_rate", "rad/s", -1.5, 1.5),
)
EVAL_TIME = 2.0  # s, T: how long a primitive runs when it is evaluated
CONTROL_PERIOD = 0.1  # s, how long the arbitrator lets a primitive run before choosing again
GOAL_RADIUS = 0.05  # m, reached when the unicycle's centre is this close


def arc(speed, turn_rate, t: float):
    """``(x, y, heading)`` (m, m, rad) after ``t`` s at constant speed and turn rate.

    From the origin facing +x; ``speed`` and ``turn_rate`` are arrays of any shape.
    """
    half = np.asarray(turn_rate) * t / 2.0
    chord = np.asarray(speed) * t * np.sinc(half / np.pi)  # np.sinc(z) = sin(pi z) / (pi z)
    return chord * np.cos(half), chord * np.sin(half), 2.0 * half


def evaluate(genes: np.ndarray):
    """Your evaluation: ``genes (n, 2)`` in [-1, 1] -> quality, behaviour, heading.

    Returns ``quality (n,)``, ``behaviour (n, 2)`` m and ``heading (n,)`` rad after
    ``EVAL_TIME`` s from rest. Replace it with your simulator or your robot.
    """
    speed, turn_rate = (p.to_physical(genes[:, k]) for k, p in enumerate(PARAMETERS))
    x, y, heading = arc(speed, turn_rate, EVAL_TIME)
    outcome = PrimitiveOutcome(x=x, y=y, heading=heading, path=np.abs(speed) * EVAL_TIME)
    return quality_metric("distance")(outcome), outcome.displacement, heading


def evolve_repertoire(seed: int) -> Repertoire:
    """MAP-Elites driven by hand: ask, evaluate, tell, until the budget is spent."""
    settings = MapElitesSettings(
        robot="unicycle",  # recorded in the file
        metric="distance",  # names the quality evaluate() computes
        bin_size=0.05,  # m, side of an archive cell
        eval_time=EVAL_TIME,
        initial_batch=2000,  # random primitives first (S_G) ...
        batch_size=500,  # ... then batches of mutants (S_B) ...
        iterations=40,  # ... this many (I)
        seed=seed,
    )
    # The archive must hold every behaviour: no primitive gets further than its top speed.
    reach = PARAMETERS[0].high * EVAL_TIME
    run = MapElites(settings, parameters=PARAMETERS, max_reach=reach)
    while not run.finished:
        genes = run.ask()
        run.tell(genes, *evaluate(genes))
    return run.repertoire()


def drive_to(repertoire: Repertoire, goal: tuple[float, float], max_cycles: int = 400) -> int:
    """Control cycles to drive from the origin (facing +x) to ``goal`` (m), as EvoRBC does."""
    mapping = MappingFunction.for_behaviours("polar", repertoire.behaviour)
    lookup = PrimitiveLookup.build(repertoire.behaviour, mapping.domain())
    tau = mapping.params[0]  # m, the repertoire's longest displacement
    speed, turn_rate = (p.to_physical(repertoire.genes[:, k]) for k, p in enumerate(PARAMETERS))
    x = y = heading = 0.0
    for cycle in range(max_cycles):
        dx, dy = goal[0] - x, goal[1] - y
        distance = math.hypot(dx, dy)
        if distance <= GOAL_RADIUS:
            return cycle
        # The "network": the goal's bearing and distance as the polar mapping's outputs.
        # m2 = 0.5 is straight ahead; m1 below 0.5 drives backward (docs/design.md section 7).
        bearing = math.remainder(math.atan2(dy, dx) - heading, 2.0 * math.pi)
        ahead = abs(bearing) <= math.pi / 2
        reach = min(1.0, distance / tau)
        m1 = 0.5 + 0.5 * reach if ahead else 0.5 - 0.5 * reach
        m2 = 0.5 + math.remainder(bearing if ahead else bearing + math.pi, 2 * math.pi) / math.pi
        k = choose(mapping, lookup, m1, m2)[0]
        # Run primitive k for one control period, from where the robot is.
        ax, ay, turned = arc(speed[k], turn_rate[k], CONTROL_PERIOD)
        x += ax * math.cos(heading) - ay * math.sin(heading)
        y += ax * math.sin(heading) + ay * math.cos(heading)
        heading += float(turned)
    return max_cycles


def main(argv: list[str] | None = None) -> None:
    """Evolve, save and reload the repertoire, then drive to three goals with it."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="unicycle.json", help="repertoire file to write")
    parser.add_argument("--plot", help="Fig. 8-style picture of the repertoire (PNG)")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args(argv)

    # Repertoire files name their robot; a robot evorbc does not ship is declared first.
    declare_robot("unicycle", len(PARAMETERS))
    repertoire = evolve_repertoire(args.seed)
    repertoire.save(args.out)
    s = repertoire.summary()
    print(
        f"unicycle repertoire: {s['count']} primitives in {s['coverage']:.0%} of the cells, "
        f"mean quality {s['mean_quality']:.3f}, {repertoire.algorithm['evaluations']} "
        f"evaluations -> {args.out}"
    )
    if args.plot:
        from offline_evolution.plots.repertoire import plot_repertoire

        plot_repertoire(repertoire, args.plot)

    loaded = Repertoire.load(args.out)  # validated, exactly what was saved
    for goal in ((1.5, 0.0), (0.5, 1.2), (-1.0, -0.4)):
        cycles = drive_to(loaded, goal)
        print(
            f"goal ({goal[0]:+.1f}, {goal[1]:+.1f}) m: "
            + (f"reached in {cycles * CONTROL_PERIOD:.1f} s" if cycles < 400 else "not reached")
        )


if __name__ == "__main__":
    main()
