# Poll the six background runs for up to $1 seconds (until all have ended), then report and pack their records.
set -u
limit=${1:-540}
end=$(( $(date +%s) + limit ))
while [ $(ls /tmp/fig/*.rc 2>/dev/null | wc -l) -lt 6 ] && [ $(date +%s) -lt $end ]; do sleep 5; done
now=$(date -u +%s); start=$(cat /tmp/fig/start.txt)
echo "elapsed since launch: $(( now - start )) s" | tee -a /tmp/fig/polls.txt
for m in her splid pchid no-select gcsl es; do
  f=$(ls /tmp/fig/$m/*/s0/metrics.jsonl 2>/dev/null | head -1)
  last=""; age=""
  if [ -n "$f" ]; then
    last=$(tail -1 $f | python3 -c "import json,sys; d=json.loads(sys.stdin.read()); print({k: d.get(k) for k in ('iteration','episodes','eval_success','eval_success_final')})" 2>/dev/null)
    age="metrics age $(( now - $(stat -c %Y $f) )) s"
  fi
  rc=$(cat /tmp/fig/$m.rc 2>/dev/null); [ -n "$rc" ] && rc="rc=${rc% *} after $(( ${rc#* } - start )) s"
  echo "$m: ${rc:-running} $age $last" | tee -a /tmp/fig/polls.txt
  tail -2 /tmp/fig/$m.log | cut -c1-200
done
nvidia-smi --query-gpu=utilization.gpu,memory.used --format=csv,noheader | tee -a /tmp/fig/polls.txt
cd /tmp && find fig -type f -not -path "*checkpoint*" \( -name "*.json" -o -name "*.jsonl" -o -name "*.log" -o -name "*.rc" -o -name "*.txt" -o -name "*.csv" -o -name "*.png" -o -name "*.cmd" \) | tar czf $OUT/fig.tgz -T -
