# Slide with the reference's pads: SPLID's default with the pads' friction on the puck lowered to 0.2 (pad_friction)
# beside the task's 1, fresh seeds 9100-9102 (chose nothing), the two side by side under MPS on one GPU; cut by the
# call's time, then each seed's policy exported for the reference evaluation.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/h3; mkdir -p $W/arms $W/export; T0=$(date +%s)
NG=$(nvidia-smi -L | wc -l); echo "gpus $NG" >> $W/times.txt
PADS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
S="python3 -m splid_jax.sweep --env slide --checkpoint-every 0 --compile-cache= --no-plot --seed 9100 --seeds 3"
STOP=${STOP:-450}
left() { echo $(( $1 - ($(date +%s) - T0) )); }
arm() {  # name gpu command...
  local n=$1 g=$2; shift 2
  CUDA_VISIBLE_DEVICES=$g timeout -k 30 $(left $STOP) "$@" --run-dir $W/arms/$n > $W/arms/$n.log 2>&1
  echo "$n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
  CUDA_VISIBLE_DEVICES=$g python3 -m splid_jax.export $W/arms/$n/sigma*-s* --out $W/export/$n > $W/export/$n.log 2>&1
  echo "export $n rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
}
nvidia-cuda-mps-control -d 2>/dev/null && echo mps >> $W/times.txt
arm splid-mu02 0 $S --env-options $PADS,pad_friction=0.2 &
arm splid-mu1 0 $S --env-options $PADS &
wait
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints 2>/dev/null
cd /tmp && tar czf $OUT/h3.tgz h3
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 2 $f; done
