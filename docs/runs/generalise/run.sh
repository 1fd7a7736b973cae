#!/bin/sh
# One screening run of docs/generalisation.md: evolve 4ws-5 on a task of tasks/, then
# evaluate the controller on the paper mazes and on the 50 held-out mazes (seed 21021),
# 20 random starts per maze. Re-running the same command resumes from the checkpoint.
# NEAT_INI (optional) is a NEAT settings file, e.g. config/neat/4ws-recurrent.ini; without
# it the robot's default NEAT settings are used, as in the runs before it existed.
#   usage: sh docs/runs/generalise/run.sh NAME [SEED] [GENERATIONS] [NEAT_INI]   (from the worktree)
set -e
name=$1; seed=${2:-1}; gens=${3:-300}; neat_ini=${4:-}
dir=docs/runs/generalise
out=$dir/$name-seed$seed
.venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/4ws-5.repertoire.json \
  --task $dir/tasks/$name.yaml --seed $seed --generations $gens --workers 1 --quiet \
  ${neat_ini:+--neat-config "$neat_ini"} \
  --out $out.arbitrator.json --checkpoint $out.checkpoint.json
for suite in paper held; do
  if [ $suite = paper ]; then extra=""; else extra="--generated 50"; fi
  .venv/bin/evorbc-evolve evaluate --arbitrator $out.arbitrator.json $extra --starts 20 \
    --perturb none --repertoire evorbc_ros/data/4ws-5.repertoire.json --json | .venv/bin/python $dir/summary.py > $out.$suite.json
done
