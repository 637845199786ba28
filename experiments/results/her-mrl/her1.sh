# HER (mrl preset) on Push, PickAndPlace and Slide, and HER (Baselines preset) on Push, 5 fresh seeds each, one GPU each.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/w; mkdir -p $W
nvidia-smi -L > $W/gpus.txt
BASE=$(python3 -c "from splid_jax.common.values import options_text as o; from splid_jax.learners.her.config import HerConfig as H, BASELINES as B; print(o(H(), **B))")
S="python3 -m splid_jax.sweep --algo her --seeds 5 --seed 7000 --checkpoint-every 0 --compile-cache= --no-plot"
cd $PWD
run() { gpu=$1; name=$2; shift 2; (export CUDA_VISIBLE_DEVICES=$gpu; date +%s > $W/$name.start; "$@" > $W/$name.log 2>&1; echo "rc=$? end=$(date +%s)" >> $W/$name.log) ; }
export -f run; export W
setsid nohup bash -c "run 0 push_mrl $S --env push --run-dir $W/push_mrl" > /dev/null 2>&1 &
setsid nohup bash -c "run 1 push_base $S --env push --num-envs 16 --eval-every 25 --iterations 1250 --her-options $BASE --run-dir $W/push_base; run 1 stage python3 experiments/stage_budget.py --env push --algos her --warm-chunks 1 --out $W/stage_mrl.json; run 1 stage_base python3 experiments/stage_budget.py --env push --algos her --her-num-envs 16 --her-options $BASE --label baselines --out $W/stage_base.json" > /dev/null 2>&1 &
setsid nohup bash -c "run 2 pnp_mrl $S --env pick_and_place --iterations 1875 --run-dir $W/pnp_mrl" > /dev/null 2>&1 &
setsid nohup bash -c "run 3 slide_mrl $S --env slide --iterations 2500 --run-dir $W/slide_mrl" > /dev/null 2>&1 &
echo launched
