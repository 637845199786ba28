#!/bin/bash
# Every run of this folder, in order, from the repository root: bash experiments/results/2026-11-29/strike-impulse/sweep.sh
# REF: a venv with mujoco 3.11.0, gymnasium-robotics 1.4.2 and this package --no-deps (here /tmp/ref311).
set -e
export PYTHONPATH=$PWD
D=experiments/results/2026-11-29/strike-impulse
PY=${PY:-/work/main/.venv/bin/python}
REF=${REF:-/tmp/ref311}
PADS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
S=$D/raw/starts100.npz
ours() { $PY $D/strike_impulse.py ours "$@" 2>&1 | tail -1; }
run() { name=$1; shift; ours --episodes 100 --label "$name" --out $D/raw/sweep_$name.json.gz "$@"; }
# the task's pads against FetchSlide-v4 on 3.11.0 and on 3.17.0 (this venv), the same 100 starts
ours --episodes 100 --starts $S --label "ours (pads, weld, 22 kg)" --out $D/raw/ours.json.gz --env-options $PADS
$REF/bin/python $D/strike_impulse.py reference --starts $S --label "FetchSlide-v4, MuJoCo 3.11.0" \
    --out $D/raw/reference.json.gz 2>&1 | tail -1
$PY $D/strike_impulse.py reference --starts $S --label "FetchSlide-v4, MuJoCo 3.17.0" \
    --out $D/raw/reference_mujoco317.json.gz 2>&1 | tail -1
# one change at a time, the same starts (the ours run draws them again from seed 0)
run mass13 --env-options finger=pads,finger_table=1,drive=weld,gripper_mass=13
run mass8 --env-options finger=pads,finger_table=1,drive=weld,gripper_mass=8
run pair_solref002 --env-options $PADS --pair 'solref=0.02 1'
run pair_solref001 --env-options $PADS --pair 'solref=0.01 1'
run pair_solimp_pad --env-options $PADS --pair 'solimp=0.99 0.99 0.01'
run pair_margin0 --env-options $PADS --pair margin=0
run pair_condim3 --env-options $PADS --pair condim=3
run weld_solref001 --env-options $PADS --weld-solref '0.01 1'
run weld_solref003 --env-options $PADS --weld-solref '0.03 1'
run weld_solref004 --env-options $PADS --weld-solref '0.04 1'
run pd_drive --env-options finger=pads,finger_table=1,gripper_mass=22
run pads_symmetric --env-options $PADS --pads-symmetric
run pads_at_strike --env-options $PADS --pad-xy=-0.0002,0.008
# a second draw of starts (seed 1), 200 episodes: the task's pads, the pads where the reference's are at the strike
ours --episodes 200 --seed 1 --starts $D/raw/starts200_seed1.npz --label "ours, seed 1" \
    --out $D/raw/ours_seed1.json.gz --env-options $PADS
ours --episodes 200 --seed 1 --pad-xy=-0.0002,0.008 --label "pads at the strike, seed 1" \
    --out $D/raw/pads_at_strike_seed1.json.gz --env-options $PADS
$REF/bin/python $D/strike_impulse.py reference --starts $D/raw/starts200_seed1.npz \
    --label "FetchSlide-v4, MuJoCo 3.11.0, seed 1" --out $D/raw/reference_seed1.json.gz 2>&1 | tail -1
# kept small: per-step traces only for ours.json.gz and the references
$PY $D/strike_impulse.py trim $D/raw/sweep_*.json.gz $D/raw/ours_seed1.json.gz $D/raw/pads_at_strike_seed1.json.gz
$PY $D/strike_impulse.py summarise $D/raw/reference.json.gz $D/raw/reference_mujoco317.json.gz $D/raw/ours.json.gz \
    $D/raw/sweep_*.json.gz $D/raw/reference_seed1.json.gz $D/raw/ours_seed1.json.gz $D/raw/pads_at_strike_seed1.json.gz
# the strike aimed 0.75 short (launched at half the speed), 50 starts of seed 0
$PY $D/strike_impulse.py ours --episodes 50 --aim-short 0.75 --starts $D/raw/starts50.npz --label "ours, aimed 0.75 short" --out $D/raw/slow_ours.json.gz
$REF/bin/python $D/strike_impulse.py reference --aim-short 0.75 --starts $D/raw/starts50.npz --label "FetchSlide-v4 3.11.0, aimed 0.75 short" --out $D/raw/slow_reference.json.gz
$PY $D/strike_impulse.py trim $D/raw/slow_ours.json.gz $D/raw/slow_reference.json.gz
