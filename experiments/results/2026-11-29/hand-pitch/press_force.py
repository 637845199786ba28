"""Our Slide's pads' normal force on the puck against the grip's reach, over a policy's pressed steps (60 episodes
from the evaluation draw), each state's contacts and forces from MJX's forward pass under the task's own physics:

    PYTHONPATH=. python experiments/results/2026-11-29/hand-pitch/press_force.py RUN [hand_pitch=1]

The reference's: ``experiments/reference/hand_tilt.py --run RUN`` (``force_q50`` by reach)."""

import sys

import jax
import jax.numpy as jnp
import numpy as np
from mujoco import mjx
from mujoco.mjx._src import support

from envs.base import data_with, make_data
from envs.fetch import hand_pitch, kernels
from envs.fetch.control import ARM_REACH_CENTER
from splid_jax.reference.policy import load_run
from splid_jax.rollout import rollout

C = np.asarray(ARM_REACH_CENTER["slide"])
cfg, env, policy, pstate, step = load_run(sys.argv[1], env_options=sys.argv[2] if len(sys.argv) > 2 else "")
E = 60
states = jax.jit(lambda k: rollout(env, policy, pstate, k, E))(jax.random.PRNGKey(0))
phys = jax.tree_util.tree_map(lambda x: x[1:].reshape((-1,) + x.shape[2:]), states.physics)  # [T*E, ...]
m = env.mj_model
pads = [m.geom(n).id for n in hand_pitch.PADS]
puck = m.geom("object").id
lay = env.layout


def forces(p):
    d = data_with(make_data(env.mjx_model), p)
    home = jnp.asarray(lay.grip_home, d.mocap_pos.dtype)
    d = d.replace(mocap_pos=d.mocap_pos.at[0].set(home + p.ctrl[0:3]))
    d = mjx.forward(env.mjx_model, d)
    c = d._impl.contact
    geom = c.geom
    f = jnp.stack([support.contact_force(env.mjx_model, d, i)[0] for i in range(geom.shape[0])])
    on = ((geom[:, 0] == puck) | (geom[:, 1] == puck)) & (
        jnp.isin(geom[:, 0], jnp.asarray(pads)) | jnp.isin(geom[:, 1], jnp.asarray(pads))
    )
    return jnp.sum(jnp.where(on & (c.dist < 0), f, 0.0)), jnp.sum(on & (c.dist < 0))


with kernels.mjx_with_kernels(env):
    fn = jax.jit(jax.vmap(forces))
    fz, n = fn(phys)
obs = np.asarray(states.obs[1:]).reshape(-1, 25)
grip, pk = obs[:, 0:3], obs[:, 3:6]
pressed = (np.asarray(n) > 0) & (grip[:, 2] - pk[:, 2] > 0.01)
reach = np.linalg.norm(grip - C, axis=1)
fz = np.asarray(fz)
print(env.hand_pitch and f"hand_pitch={env.hand_pitch}" or "upright", "pressed share", round(pressed.mean(), 3))
for lo in np.arange(0.80, 1.125, 0.05):
    s = pressed & (reach >= lo) & (reach < lo + 0.05)
    if s.sum() > 5:
        q = np.percentile(fz[s], [10, 50, 90]).round(0)
        print(f"  reach {lo:.2f}-{lo + 0.05:.2f} n {s.sum():4d} pad-puck normal force q10/50/90 {q} N")
