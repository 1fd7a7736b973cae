# Two commands for a new user; each creates .venv and installs what it needs.
#   make demo   runs the main job on the shipped default
#   make test   runs the linter and the test suite (what CI runs)
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.evorbc-installed
OUT    ?= demo-output
# The checkout's evorbc_ros/ and sim_bridge/ folders are ROS package folders, not the Python
# packages inside them: never import from the current folder (python -P; docs/design.md
# section 10).
export PYTHONSAFEPATH := 1

.PHONY: demo demo-hexapod demo-a1 demo-repertoire demo-evolve test test-fast fuzz lint bench bench-generalise clean

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --disable-pip-version-check -e ".[dev]"
	touch $(STAMP)

# The main job: the shipped 4ws-5 controller driving the simulated robot through a maze,
# as five ROS 2 nodes in separate processes over DDS (lockstep), with a trajectory picture.
demo: $(STAMP)
	$(VENV)/bin/evorbc-sim --maze obstacle --plot $(OUT)/obstacle-run.png \
		--result $(OUT)/obstacle-run.json
	@echo "demo: open $(OUT)/obstacle-run.png; try another maze with: $(VENV)/bin/evorbc-sim --maze gaps"

# The same for the hexapod: the shipped hexapod controller walks the 2 x 8 m laser maze
# (PyBullet dynamics at 50 Hz, joint trajectories at 10 Hz through the graph).
demo-hexapod: $(STAMP)
	$(VENV)/bin/evorbc-sim --robot hexapod --plot $(OUT)/hexapod-run.png \
		--result $(OUT)/hexapod-run.json
	@echo "demo-hexapod: open $(OUT)/hexapod-run.png"

# The same for Unitree's A1 quadruped (pybullet_data's URDF; docs/a1.md): the shipped A1
# controller walks its 8 x 2.5 m maze (PyBullet at 100 Hz, joint trajectories at 100 Hz
# points, 10 Hz messages, through the graph).
demo-a1: $(STAMP)
	$(VENV)/bin/evorbc-sim --robot a1 --plot $(OUT)/a1-run.png --result $(OUT)/a1-run.json
	@echo "demo-a1: open $(OUT)/a1-run.png"

# A MAP-Elites repertoire for the 4ws-5 robot at the paper's full budget (1.01M evaluations;
# README, "How long things take", has measured times).
demo-repertoire: $(STAMP)
	$(VENV)/bin/evorbc-evolve repertoire --robot 4ws-5 --seed 1 \
		--out $(OUT)/4ws-5.repertoire.json --plot $(OUT)/4ws-5.repertoire.png \
		--csv $(OUT)/4ws-5.repertoire.csv

# A whole EvoRBC run: repertoire, then 1000 generations of NEAT, then a replay (9 min of
# evolution on 2 cores with the machine to itself; README, "How long things take").
demo-evolve: demo-repertoire
	$(VENV)/bin/evorbc-evolve arbitrator --repertoire $(OUT)/4ws-5.repertoire.json --seed 1 \
		--out $(OUT)/4ws-5.arbitrator.json
	$(VENV)/bin/evorbc-evolve replay --arbitrator $(OUT)/4ws-5.arbitrator.json \
		--plot $(OUT)/4ws-5.replay.png --heatmap $(OUT)/4ws-5.selection.png

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

# Three workers on two cores, a test file each at a time (module fixtures such as the built
# wheel are made once): the suite waits on 10 Hz ROS graphs, subprocesses and Ray clusters
# more than it computes (a -n 3 run: 875 s of CPU in 525 s). The multi-process tests claim
# their ROS domains (tests/ros_domains.py), so the workers never share a graph.
WORKERS ?= -n 3 --dist loadfile

test: lint
	$(PY) -m pytest -q $(WORKERS)

# The suite without the tests marked slow (Ray clusters, killed and resumed runs, full
# budgets, the plugin package): a few minutes, for working on the code.
test-fast: lint
	$(PY) -m pytest -q -m "not slow" $(WORKERS)

# The whole fuzz corpus (tests/fuzz): every named hostile file at full size (a 3 M-primitive
# repertoire, a 16 GiB zip bomb) and 100 mutants of each format, loaded through the command
# line; the table goes to docs/fuzz.md. The suite runs a fast subset (tests/test_fuzz.py).
fuzz: $(STAMP)
	$(PY) tests/fuzz/sweep.py --big --per-kind 100 --record docs/fuzz.md

bench: $(STAMP)
	$(PY) bench/bench_repertoire.py
	$(PY) bench/bench_arbitrator.py
	$(PY) bench/bench_ros.py

# Generated-maze training and held-out evaluation (docs/performance.md): about 20 minutes.
bench-generalise: $(STAMP)
	$(PY) bench/bench_training_mazes.py
	$(PY) bench/bench_training_mazes_legged.py --episode-time 60 --generations 2
	$(PY) bench/bench_evaluate.py

clean:
	rm -rf $(VENV) $(OUT) build *.egg-info
