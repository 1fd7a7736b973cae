#!/bin/sh
# Regenerates measured 4ws-5 figures of docs/generalisation.md whose run files were not
# kept, all with 4WS evaluations (`evorbc-evolve evaluate`, single process, seconds each):
#   1. section "4ws-5 on the paper mazes": the shipped 4ws-5 controller
#      (evorbc_ros/data/4ws-5.arbitrator.json, evaluate's default) from 20 random starts
#      per paper maze, unperturbed, start seeds 1, 2, 3 ("Seeds 1-3 give 93 %, 94 % and 93 %")
#      -> paper-seed{1,2,3}-none.*, paper-seeds.txt
#   2. section "Perturbed worlds": the same controller on the 50 held-out mazes (seed 21021,
#      20 starts each, seed 0) with one quantity of the `realistic` set at a time, at its
#      `realistic` range (perturb-*.yaml, written here) -> heldout-*.*,
#      heldout-one-at-a-time.txt
#   3. section "4ws-5 on 50 held-out mazes": its held-out results by target kind and by
#      obstacle kind, unperturbed and under `realistic` -> mazes-21021.json,
#      heldout-by-kind.{txt,json}
#   4. section "Why the eight-beam controllers generalise less": four arbitrators on 30
#      generated mazes of seed 777, 10 starts each (seed 0), unperturbed, each with its own
#      task and sensors -> seed777-*.*, mazes-777.json, seed777-by-kind.{txt,json}
# Per run: NAME.json (the report without its episodes, as docs/runs/generalise/summary.py
# keeps it, plus "failed_stalled" counted from the episodes: by_kind.py summarise) and
# NAME.txt (evaluate's table). Resumable: an output that exists is not made again (delete
# it to remake it). Run from the repository root:  sh docs/runs/generalisation/extra/make.sh
set -eu

OUT=docs/runs/generalisation/extra
EVO=.venv/bin/evorbc-evolve
PY=.venv/bin/python
REP=evorbc_ros/data/4ws-5.repertoire.json
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT INT TERM

# run NAME EVALUATE-ARGS...: one evaluation -> $OUT/NAME.json and $OUT/NAME.txt
run() {
    name=$1
    shift
    if [ -s "$OUT/$name.json" ] && [ -s "$OUT/$name.txt" ]; then
        echo "have $name"
        return
    fi
    echo "run  $name: evaluate $*"
    "$EVO" evaluate "$@" --out "$TMP/full.json" > "$TMP/table.txt"
    "$PY" "$OUT/by_kind.py" summarise < "$TMP/full.json" > "$TMP/summary.json"
    mv "$TMP/table.txt" "$OUT/$name.txt"
    mv "$TMP/summary.json" "$OUT/$name.json"
}

# mazes SEED COUNT: the generator's record of each maze (kinds, target mode)
mazes() {
    if [ ! -s "$OUT/mazes-$1.json" ]; then
        echo "make mazes-$1.json"
        "$EVO" mazes --robot 4ws-5 --count "$2" --seed "$1" --out "$TMP/mazes-$1" \
            --plot none --json > "$TMP/mazes.json"
        mv "$TMP/mazes.json" "$OUT/mazes-$1.json"
    fi
}

# table FILE COMMAND...: a table made from the summaries, unless it exists
table() {
    file=$1
    shift
    if [ ! -s "$OUT/$file" ]; then
        echo "make $file"
        "$@" > "$TMP/table.txt"
        mv "$TMP/table.txt" "$OUT/$file"
    fi
}

# 1. paper mazes, start seeds 1-3
for s in 1 2 3; do
    run "paper-seed$s-none" --starts 20 --perturb none --seed "$s"
done
table paper-seeds.txt "$PY" "$OUT/by_kind.py" runs \
    "$OUT/paper-seed1-none.json" "$OUT/paper-seed2-none.json" "$OUT/paper-seed3-none.json"

# 2. one quantity of `realistic` at a time (its ranges, config/perturbations/realistic.yaml;
# the kinematic 4WS model applies only these six)
one() {
    if [ ! -s "$OUT/perturb-$1.yaml" ]; then
        printf '# `realistic` (config/perturbations/realistic.yaml) with only %s perturbed\nname: realistic-%s\ndescription: %s alone, at its realistic range\n%s: %s\n' \
            "$1" "$1" "$1" "$1" "$2" > "$OUT/perturb-$1.yaml"
    fi
}
one wheel_speed_gain '[0.85, 1.1]'
one latency_cycles '[0, 1]'
one range_noise '[0.0, 0.02]'
one dropout '[0.0, 0.05]'
one start_position '[0.0, 0.05]'
one start_heading_deg '[0.0, 10]'

run heldout-none --generated 50 --starts 20 --perturb none
run heldout-realistic --generated 50 --starts 20 --perturb realistic
for q in wheel_speed_gain latency_cycles range_noise dropout start_position start_heading_deg; do
    run "heldout-$q" --generated 50 --starts 20 --perturb "$OUT/perturb-$q.yaml"
done
table heldout-one-at-a-time.txt "$PY" "$OUT/by_kind.py" runs \
    "$OUT/heldout-none.json" "$OUT/heldout-realistic.json" \
    "$OUT/heldout-dropout.json" "$OUT/heldout-range_noise.json" \
    "$OUT/heldout-latency_cycles.json" "$OUT/heldout-start_position.json" \
    "$OUT/heldout-start_heading_deg.json" "$OUT/heldout-wheel_speed_gain.json"

# 3. held-out results by target and obstacle kind
mazes 21021 50
table heldout-by-kind.txt "$PY" "$OUT/by_kind.py" kinds "$OUT/mazes-21021.json" \
    "$OUT/heldout-none.json" "$OUT/heldout-realistic.json" --json "$OUT/heldout-by-kind.json"

# 4. seed-777 mazes, four arbitrators (their own task and sensors: no --task)
G=docs/runs/generalise
for a in "$G/fresh-k10-g8-rnn-path-seed1" "$G/ship/4ws-5-r8-p1-seed1-g300" \
    "$G/ship/4ws-5-r8-p3-seed1" "$G/ship/4ws-5-s6-p1-seed1-g300"; do
    run "seed777-$(basename "$a")" --arbitrator "$a.arbitrator.json" --repertoire "$REP" \
        --generated 30 --generated-seed 777 --starts 10 --seed 0 --perturb none
done
mazes 777 30
table seed777-by-kind.txt "$PY" "$OUT/by_kind.py" kinds "$OUT/mazes-777.json" \
    "$OUT/seed777-fresh-k10-g8-rnn-path-seed1.json" "$OUT/seed777-4ws-5-r8-p1-seed1-g300.json" \
    "$OUT/seed777-4ws-5-r8-p3-seed1.json" "$OUT/seed777-4ws-5-s6-p1-seed1-g300.json" \
    --json "$OUT/seed777-by-kind.json"
echo done
