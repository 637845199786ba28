# SPLID default on Slide with the reference pads (the intended default), seeds SEED.. (N of them) in one process to
# its default budget, 35,840 episodes (70 x 512), cut by its own timeout if not there by then; then each seed policy
# exported for the reference evaluation.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site XLA_FLAGS=--xla_gpu_enable_triton_gemm=false
W=/tmp/l3; mkdir -p $W/arms $W/export; T0=$(date +%s)
OPTS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
H="python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot --iterations 70"
STOP=${STOP:-495}
left() { echo $(( $1 - ($(date +%s) - T0) )); }
arm() {  # name first-seed seeds
  timeout -k 20 $(left $STOP) $H --seed $2 --seeds $3 --env-options $OPTS --run-dir $W/arms/$1 > $W/arms/$1.log 2>&1
  echo "$1 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  timeout -k 5 40 python3 -m splid_jax.export $W/arms/$1/sigma*-s* --out $W/export/$1 > $W/export/$1.log 2>&1
  echo "export $1 rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
arm a ${SEED:-9200} ${N:-3}
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp
for d in l3/export/*/*; do [ -d "$d" ] && tar czf $OUT/$(basename $d).tgz $d; done
find l3 -type f \( -name '*.json' -o -name '*.jsonl' -o -name '*.log' -o -name '*.txt' \) -not -path 'l3/export/*/*/*' -size -4M | tar czf $OUT/runs.tgz -T -
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 2 $f; done
