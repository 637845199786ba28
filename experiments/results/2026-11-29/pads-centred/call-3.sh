# SPLID default on Slide with the reference pads at their corrected centres, fresh seeds 9200-9204 to 15,360 episodes
# (30 x 512), seeds 9200-9202 and 9203-9204 as two processes side by side under MPS on one GPU, each cut by its own
# timeout; then each seed policy exported for the reference evaluation.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
W=/tmp/s5; mkdir -p $W/arms $W/export; T0=$(date +%s)
OPTS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
H="python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot --iterations 30"
STOP=${STOP:-480}
left() { echo $(( $1 - ($(date +%s) - T0) )); }
arm() {  # name first-seed seeds
  timeout -k 20 $(left $STOP) $H --seed $2 --seeds $3 --env-options $OPTS --run-dir $W/arms/$1 > $W/arms/$1.log 2>&1
  echo "$1 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  timeout -k 5 40 python3 -m splid_jax.export $W/arms/$1/sigma*-s* --out $W/export/$1 > $W/export/$1.log 2>&1
  echo "export $1 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
arm a 9200 3 &
arm b 9203 2 &
wait
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp
for d in s5/export/*/*; do [ -d "$d" ] && tar czf $OUT/$(basename $d).tgz $d; done
find s5 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 's5/export/*/*/*' -size -4M | tar czf $OUT/runs.tgz -T -
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 2 $f; done
