python -m splid_jax.figures fig3 --env push --episodes 100000 --methods es --set checkpoint_every=0 --out /tmp/fig/es --compile-cache= --quiet
