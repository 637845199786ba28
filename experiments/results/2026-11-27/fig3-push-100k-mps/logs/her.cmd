python -m splid_jax.figures fig3 --env push --episodes 100000 --methods her --set checkpoint_every=0 --out /tmp/fig/her --compile-cache= --quiet
