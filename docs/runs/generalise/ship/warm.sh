#!/bin/sh
# The warm-start experiment of docs/generalisation.md ("Continuing a generalising
# population on the paper mazes"): the population of 4ws-5-p8-p1s05 seed 1 at generation
# 1000 (its kept checkpoint), continued for 300 generations with 3 random starts in each
# paper maze instead of 1 (task-p8-p3s05.yaml: the paper mazes 15 of a genome's 25
# episodes), to see whether a population that generalises learns `corridors` when the paper
# mazes weigh more. evorbc-evolve has no option for a run whose task changes midway, so the
# checkpoint is copied and its recorded task edited (samples_per_maze 1 -> 3) before the
# run resumes from it: an experiment, not a way to make a shipped controller.
#   usage: sh docs/runs/generalise/ship/warm.sh
set -e
dir=docs/runs/generalise/ship
out=$dir/4ws-5-p8-p1s05-p3warm-seed1
if [ ! -f $out.checkpoint.json ] && [ ! -f $out.arbitrator.json ]; then
  .venv/bin/python - $dir/4ws-5-p8-p1s05-seed1.checkpoint.json $out.checkpoint.json <<'PY'
import json, sys
from evorbc_ros.atomic_io import atomic_write_text
data = json.load(open(sys.argv[1]))
assert data["population"]["generation"] == 1000 and data["settings"]["task"]["samples_per_maze"] == 1
data["settings"]["task"]["samples_per_maze"] = 3
atomic_write_text(sys.argv[2], json.dumps(data))
PY
fi
if [ ! -f $out.arbitrator.json ] || [ -f $out.checkpoint.json ]; then
  .venv/bin/evorbc-evolve arbitrator --repertoire evorbc_ros/data/4ws-5.repertoire.json \
    --task $dir/task-p8-p3s05.yaml --neat-config config/neat/4ws-recurrent.ini --seed 1 \
    --workers 1 --quiet --config $dir/select-reach.yaml --checkpoint $out.checkpoint.json \
    --generations 1300 --keep-checkpoint --out $out.arbitrator.json
fi
sh docs/runs/generalise/evaluate.sh $out
