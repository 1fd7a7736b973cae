"""The largest count an option or a settings file may ask for (docs/design.md section 12).

A count far beyond any real run (``--generations 10**30``, a study of ``10**12`` seeds,
``num_hidden = 5000``) used to start work that could never end on this kind of machine
(2 to a few dozen cores), often before its first progress line, so that it looked like a
hang. Each bound is well above the paper's value and every shipped setting, and is
checked with the option or the setting, before any work; a value past it is refused in
one line naming the option or key and its bound. Settings whose cost is memory
(``samples_per_maze``, ``post_samples``, ``batch_size``, ``--starts``, ``--episodes``)
are bounded by :mod:`offline_evolution.memory` instead, which names the setting to lower.
"""

from __future__ import annotations

#: NEAT generations of one run. The paper: 1000 (4WS), 200 (hexapod); a 4WS generation
#: takes about 1 s, so the bound is a day of one core.
GENERATIONS = 100_000
#: MAP-Elites: random solutions of the first batch (S_G). The paper: 10,000 and 25,000.
INITIAL_BATCH = 100_000_000
#: MAP-Elites: iterations after the first batch (I). The paper: 1000.
ITERATIONS = 1_000_000
#: MAP-Elites: evaluations of a whole run, S_G + I x S_B. The paper: about 10^6; the 4WS
#: kernels evaluate about 20,000 primitives a second on one core, so 10^9 is half a day.
EVALUATIONS = 1_000_000_000
#: Generated mazes of one command (``mazes --count``, ``evaluate --generated``): each
#: takes about 0.1 s to generate and prove solvable, so the bound is about 20 min.
MAZES = 10_000
#: Seeds of one study setting. The paper: 30.
SEEDS = 1_000
#: Settings of one study (the grid's combinations). The shipped bin-time study: 29.
STUDY_SETTINGS = 10_000
#: Runs of one study (settings x seeds). The shipped bin-time study: 870.
STUDY_RUNS = 100_000
#: Ray task retries of one study run.
RETRIES = 100
#: NEAT [NEAT] pop_size. The paper: 150. Each genome is a Python object graph: creating
#: 10,000 takes seconds, and each generation runs them all.
POP_SIZE = 10_000
#: NEAT [EvoRBCGenome] num_hidden, the hidden nodes each new genome starts with. The
#: paper: 0 (NEAT adds nodes as it needs them). neat-python creates a population of 150
#: genomes with 100 hidden nodes in about 5 s, and the cost grows with both.
NUM_HIDDEN = 100
#: numba threads of one study run (``evorbc-study run --threads``): far more threads than
#: any machine's cores only adds switching; 10^6 made numba's thread pool crash.
THREADS = 256
#: Processes simulating robots in PyBullet (``--workers``, ``evorbc-study run --jobs``),
#: each about 100 MB; with ``--cluster`` they run on the cluster's machines.
WORKERS = 1024
