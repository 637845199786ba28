# Waits up to $1 seconds for the runs, then packs their metrics, configs and logs into $OUT (checkpoints stay).
W=/tmp/w; t0=$(date +%s)
while [ $(( $(date +%s) - t0 )) -lt $1 ]; do
  n=$(grep -l "^rc=" $W/*.log 2>/dev/null | wc -l); [ "$n" -ge 6 ] && break; sleep 10
done
for r in push_mrl push_base pnp_mrl slide_mrl; do
  tar czf $OUT/$r.tgz --exclude=checkpoints -C $W $r $r.log $r.start 2>/dev/null
done
tar czf $OUT/misc.tgz -C $W gpus.txt $(cd $W; ls stage* 2>/dev/null) 2>/dev/null
for r in push_mrl push_base pnp_mrl slide_mrl stage stage_base; do echo "== $r"; tail -c 600 $W/$r.log 2>/dev/null; done
nvidia-smi --query-gpu=index,utilization.gpu,memory.used --format=csv
