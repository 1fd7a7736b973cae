#!/bin/sh
# Candidate for the shipped generalising 4ws-5 controller (docs/generalisation.md, issue 21
# item 5): the shipped generated-maze task (config/tasks/maze-4ws-generated.yaml: the paper
# mazes plus 10 fresh generated mazes a generation, the 8-sector goal radar) with recurrent
# networks, 1000 generations, then the held-out evaluation of run.sh's three suites.
# Re-running the same command resumes from the checkpoint and skips what is done.
#   usage: sh docs/runs/generalise/ship/run.sh [SEED]   (from the repository's root)
# (Edit this file only by replacing it, never in place: a running sh reads it as it goes.)
set -e
seed=${1:-1}
dir=docs/runs/generalise/ship
out=$dir/4ws-5-general-seed$seed
if [ ! -f $out.arbitrator.json ] || [ -f $out.checkpoint.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/4ws-5.repertoire.json \
    --task config/tasks/maze-4ws-generated.yaml --neat-config config/neat/4ws-recurrent.ini \
    --seed $seed --generations 1000 --workers 1 --quiet \
    --out $out.arbitrator.json --checkpoint $out.checkpoint.json
fi
for suite in paper held heldr; do
  [ -f $out.$suite.json ] && continue
  case $suite in
    paper) extra="--perturb none" ;;
    held) extra="--generated 50 --perturb none" ;;
    heldr) extra="--generated 50 --perturb realistic" ;;
  esac
  .venv/bin/evorbc-evolve evaluate --arbitrator $out.arbitrator.json $extra --starts 20 \
    --repertoire evorbc_ros/data/4ws-5.repertoire.json --json | .venv/bin/python docs/runs/generalise/summary.py > $out.$suite.tmp
  mv $out.$suite.tmp $out.$suite.json
done
