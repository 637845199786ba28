cd /work/main
P=".venv/bin/python -m"
t() { n=$1; shift; s=$(date +%s); "$@" > /tmp/pp/$n.log 2>&1; echo "$n rc=$? $(( $(date +%s) - s )) s" >> /tmp/pp/times.txt; }
t point $P splid_jax.sweep --env point --seeds 4 --preset paper --compile-cache '' --run-dir /tmp/pp/point
t reach $P splid_jax.sweep --env reach --seeds 4 --preset paper --compile-cache '' --run-dir /tmp/pp/reach
t sawyer $P splid_jax.train --env sawyer_door --preset paper --compile-cache '' --run-dir /tmp/pp/sawyer
t reacher $P splid_jax.train --env reacher --preset paper --compile-cache '' --run-dir /tmp/pp/reacher
