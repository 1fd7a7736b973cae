#!/bin/bash
# The A1 comparison (docs/a1.md, "EvoRBC against standard NEAT"): EvoRBC and standard
# NEAT, seeds 1-3, seed by seed, at the stated budget of config/arbitrator/a1-comparison.yaml
# (population 50; EvoRBC 100 generations, standard NEAT 100 + 133). Every run checkpoints
# each generation next to its output and resumes from it; finished runs are skipped: run
# this script again after an interruption. It writes the table and curves to
# docs/runs/a1/comparison/a1-check.md and .png at the end.
# Usage: nohup setsid nice -n 10 docs/runs/a1/comparison.sh >> docs/runs/a1/comparison.log 2>&1 &
set -e
cd "$(dirname "$0")/../../.."
exec .venv/bin/python -m offline_evolution.experiments.legged_check --robot a1 \
    --repertoire docs/runs/a1/repertoire-seed1/a1-seed1.repertoire.json \
    --out docs/runs/a1/comparison --seeds 3 --standard-seeds 3 \
    --config config/arbitrator/a1-comparison.yaml --standard-extra 133 \
    --workers "${EVORBC_A1_WORKERS:-2}"
