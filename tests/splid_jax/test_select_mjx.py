"""SELECT's work queue on an MJX task (Push): the lanes' verdicts equal each candidate replayed alone."""

import jax
import jax.numpy as jnp
import numpy as np

import envs
from envs.fetch import scripted
from splid_jax.explore import Trajectory
from splid_jax.select import policy_reaches, select

T, H, N = 20, 4, 3


class ScriptedPolicy:
    """The scripted pusher as SELECT's policy: it solves some relabelled goals, not others."""

    def act(self, _, obs, goal):
        return scripted.push(obs, goal)


def test_push_queue_verdicts_match_single_replays():
    env = envs.make("push", max_episode_steps=T)
    policy = ScriptedPolicy()

    def roll(key):
        k0, k1 = jax.random.split(key)
        s0 = jax.vmap(env.reset)(jax.random.split(k0, N))

        def one(s, k):
            a = jnp.clip(scripted.push(s.obs, s.desired_goal) + 0.3 * jax.random.normal(k, (N, 4)), -1, 1)
            nxt = jax.vmap(env.step)(s, a)
            return nxt, (s, a, nxt.achieved_goal, nxt.invalid)

        _, (states, acts, ag, inv) = jax.lax.scan(one, s0, jax.random.split(k1, T))
        return Trajectory(
            states, acts, jnp.concatenate([s0.achieved_goal[None], ag]), jnp.concatenate([s0.invalid[None], inv])
        )

    traj = jax.jit(roll)(jax.random.PRNGKey(0))
    cands = jax.jit(lambda tr: select(env, policy, None, tr, H, jnp.int32(H), True, 0.1))(traj)
    starts = jax.tree_util.tree_map(lambda x: x.reshape((T * N,) + x.shape[2:]), traj.states)
    valid = np.asarray(cands.valid)
    idx = np.flatnonzero(valid)
    alone = jax.jit(
        jax.vmap(
            lambda i: policy_reaches(
                env,
                policy,
                None,
                jax.tree_util.tree_map(lambda x: x[i % (T * N)], starts),
                cands.goal[i],
                i // (T * N) + 1,
            )
        )
    )(jnp.asarray(idx))
    alone = np.asarray(alone)
    assert len(idx) > 0 and 0 < alone.sum() < len(idx)
    np.testing.assert_array_equal(np.asarray(cands.accept)[idx], ~alone)
    assert not np.asarray(cands.accept)[~valid].any()
