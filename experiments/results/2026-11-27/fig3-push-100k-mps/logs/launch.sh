# Figure 3 on Push at 100,000 episodes, six methods side by side on one GPU under CUDA MPS, compile cache off.
set -u
mkdir -p /tmp/site && [ -f /tmp/site/.done ] || { tar xJf .site/site312.tar.xz -C /tmp/site && touch /tmp/site/.done; }
rm -rf /tmp/code && mkdir -p /tmp/code && tar --exclude=./.site --exclude=./.git --exclude=./experiments/results -cf - . | tar xf - -C /tmp/code && cd /tmp/code
python -m compileall -q /tmp/site /tmp/code > /dev/null 2>&1
export PYTHONPATH=/tmp/site:/tmp/code PYTHONUNBUFFERED=1 XLA_PYTHON_CLIENT_PREALLOCATE=false
mkdir -p /tmp/fig
{ nvidia-smi --query-gpu=name,driver_version --format=csv,noheader; date -u; } > /tmp/fig/device.txt
setsid nvidia-cuda-mps-control -d && echo "mps started $(date -u +%s)" >> /tmp/fig/device.txt
date -u +%s > /tmp/fig/start.txt
for m in her splid pchid no-select gcsl es; do
  ck=0; case $m in splid|pchid) ck=100;; esac
  cmd="python -m splid_jax.figures fig3 --env push --episodes 100000 --methods $m --set checkpoint_every=$ck --out /tmp/fig/$m --compile-cache= --quiet"
  echo "$cmd" > /tmp/fig/$m.cmd
  setsid nohup sh -c "$cmd > /tmp/fig/$m.log 2>&1; echo \$? \$(date -u +%s) > /tmp/fig/$m.rc" > /dev/null 2>&1 < /dev/null &
done
sleep 2; echo "processes: $(pgrep -fc 'splid_jax.figures')" >> /tmp/fig/device.txt
bash /tmp/code/.dev/fig35_poll.sh 520
