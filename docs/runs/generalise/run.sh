#!/bin/sh
# One screening run of docs/generalisation.md: evolve 4ws-5 on a task of tasks/, then
# evaluate the controller on the paper mazes and on the 50 held-out mazes (seed 21021),
# 20 random starts per maze, unperturbed and under `realistic`. Re-running the same command
# resumes from the checkpoint and skips what is done.
# NEAT_INI (optional) is a NEAT settings file, e.g. config/neat/4ws-recurrent.ini; without
# it the robot's default NEAT settings are used, as in the runs before it existed.
#   usage: sh docs/runs/generalise/run.sh NAME [SEED] [GENERATIONS] [NEAT_INI]   (from the worktree)
# (Edit this file only by replacing it, never in place: a running sh reads it as it goes.)
set -e
name=$1; seed=${2:-1}; gens=${3:-300}; neat_ini=${4:-}
dir=docs/runs/generalise
out=$dir/$name-seed$seed
if [ ! -f $out.arbitrator.json ] || [ -f $out.checkpoint.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/4ws-5.repertoire.json \
    --task $dir/tasks/$name.yaml --seed $seed --generations $gens --workers 1 --quiet \
    ${neat_ini:+--neat-config "$neat_ini"} \
    --out $out.arbitrator.json --checkpoint $out.checkpoint.json
fi
# A run trained with other episodes than the others is evaluated like them: tasks/NAME.eval.yaml.
evaltask=""
[ -f $dir/tasks/$name.eval.yaml ] && evaltask="--task $dir/tasks/$name.eval.yaml"
sh $dir/evaluate.sh $out $evaltask
