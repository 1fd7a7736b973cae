#!/bin/sh
# One legged screening run of docs/generalisation.md: evolve ROBOT's arbitrator on a task of
# tasks/ with its shipped repertoire, then evaluate it from 20 random starts in its own maze
# and on the 10 held-out mazes (seed 21021) x 20 starts (issue 21 item 5), unperturbed and under `realistic`, with
# the episodes it was trained with. Re-running the same command resumes from the checkpoint.
#   usage: sh docs/runs/generalise/run-legged.sh ROBOT NAME [SEED] [GENERATIONS] [NEAT.ini]
set -e
robot=$1; name=$2; seed=${3:-1}; gens=${4:-200}; neat=${5:+--neat-config $5}
dir=docs/runs/generalise
out=$dir/$name-seed$seed
if [ ! -f $out.arbitrator.json ] || [ -f $out.checkpoint.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/$robot.repertoire.json \
    --task $dir/tasks/$name.yaml --seed $seed --generations $gens --quiet $neat \
    --out $out.arbitrator.json --checkpoint $out.checkpoint.json
fi
for suite in own held ownr heldr; do
  [ -f $out.$suite.json ] && continue
  case $suite in
    own) extra="--starts 20 --perturb none" ;;
    held) extra="--generated 10 --starts 20 --perturb none" ;;
    ownr) extra="--starts 20 --perturb realistic" ;;
    heldr) extra="--generated 10 --starts 20 --perturb realistic" ;;
  esac
  .venv/bin/evorbc-evolve evaluate --arbitrator $out.arbitrator.json $extra \
    --repertoire evorbc_ros/data/$robot.repertoire.json --json | .venv/bin/python $dir/summary.py > $out.$suite.tmp
  mv $out.$suite.tmp $out.$suite.json
done
