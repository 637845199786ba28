# Call 1 (2 GPUs): GPU 0: the paper preset on Slide (seeds 2000-2004) and PickAndPlace (6000-6004), the tuned rows'
# seeds, under MPS. GPU 1: SPLID Push arms on tuning seeds 1000-1004, BC work per new pair (bc_reuse) x cap x rate.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/e1; mkdir -p $W/arms; T0=$(date +%s)
nvidia-smi -L > $W/gpus.txt; nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
C="--checkpoint-every 0 --compile-cache= --no-plot --seeds 5"
arm() { g=$1; n=$2; shift 2; CUDA_VISIBLE_DEVICES=$g timeout -k 10 $(( 545 - ($(date +%s) - T0) )) python3 -m splid_jax.sweep $C --run-dir $W/arms/$n "$@" > $W/arms/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt; }
arm 0 paper-slide --env slide --preset paper --seed 2000 &
arm 0 paper-pnp --env pick_and_place --preset paper --seed 6000 &
P="--env push --seed 1000 --iterations 80"
arm 1 reuse200 $P --vary bc_reuse=0,10,20,40 &
arm 1 reuse400 $P --bc-steps 400 --vary bc_reuse=40,80 --vary learning_rate=5e-4,2.5e-4 &
wait
cd $W && find arms -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' \) -size -4M | tar czf $OUT/e1.tgz -T - times.txt gpus.txt
cat $W/times.txt; for f in $W/arms/*.log; do echo "== $f"; tail -n 2 $f; done
