#!/bin/sh
# The four suites of docs/generalisation.md for the 4ws-5 arbitrator STEM.arbitrator.json:
# STEM.paper.json (the five paper mazes), STEM.held.json (the 50 held-out mazes, seed 21021),
# STEM.heldr.json (those under `realistic`) and STEM.paperr.json (the paper mazes under
# `realistic`; added 2026-11-26), 20 random starts per maze (seed 0), each a
# summary (summary.py) without the episodes. A suite already evaluated is skipped. EXTRA
# (e.g. --task FILE: the episodes and sensors of a run trained with others) goes to every
# evaluation.
#   usage: sh docs/runs/generalise/evaluate.sh STEM [EXTRA...]
set -e
out=$1; shift
for suite in paper held heldr paperr; do
  [ -f $out.$suite.json ] && continue
  case $suite in
    paper) extra="--perturb none" ;;
    held) extra="--generated 50 --perturb none" ;;
    heldr) extra="--generated 50 --perturb realistic" ;;
    paperr) extra="--perturb realistic" ;;
  esac
  .venv/bin/evorbc-evolve evaluate --arbitrator $out.arbitrator.json $extra "$@" --starts 20 \
    --repertoire evorbc_ros/data/4ws-5.repertoire.json --json | .venv/bin/python docs/runs/generalise/summary.py > $out.$suite.tmp
  mv $out.$suite.tmp $out.$suite.json
done
