# Slide with the reference's box pads on the corrected box-cylinder contact (plane support, 4 ms), fresh seeds
# 9000-9004: GPU 0 SPLID's default, GPU 1 HER (mrl) at 16 envs, bf16, cuBLAS products; both cut by the call's
# time, then each member's policy exported for the reference evaluation.
export NCCL_NVLS_ENABLE=0 PYTHONUNBUFFERED=1
python3 -m pip install -q --no-index --no-deps --no-compile --no-cache-dir --upgrade --target /tmp/site .whl/*.whl || exit 1
export PYTHONPATH=$PWD:/tmp/site
W=/tmp/f5; mkdir -p $W/arms $W/export; T0=$(date +%s)
PADS=finger=pads,finger_table=1,drive=weld,gripper_mass=22
S="python3 -m splid_jax.sweep --env slide --seeds 5 --seed 9000 --checkpoint-every 0 --compile-cache= --no-plot --env-options $PADS"
F=--xla_gpu_enable_triton_gemm=false
left() { echo $(( $1 - ($(date +%s) - T0) )); }
(CUDA_VISIBLE_DEVICES=0 timeout -k 30 $(left 320) $S --run-dir $W/arms/splid > $W/arms/splid.log 2>&1; echo "splid rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
 CUDA_VISIBLE_DEVICES=0 python3 -m splid_jax.export $W/arms/splid/sigma*-s90* --out $W/export/splid > $W/export/splid.log 2>&1; echo "export splid rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
(CUDA_VISIBLE_DEVICES=1 XLA_FLAGS=$F timeout -k 30 $(left 320) $S --algo her --run-dir $W/arms/her --iterations 1250 --num-envs 16 --her-compute-dtype bfloat16 > $W/arms/her.log 2>&1; echo "her rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt
 CUDA_VISIBLE_DEVICES=1 python3 -m splid_jax.export $W/arms/her/sigma*-s90* --out $W/export/her > $W/export/her.log 2>&1; echo "export her rc=$? $(( $(date +%s) - T0 ))s" >> $W/times.txt) &
wait
rm -rf $W/arms/*/checkpoints $W/arms/*/*/checkpoints
cd /tmp && find f5 -type f -size -8M | tar czf $OUT/f5.tgz -T -
ls -la $OUT; cat $W/times.txt; for f in $W/arms/*.log $W/export/*.log; do echo "== $f"; tail -n 3 $f; done
