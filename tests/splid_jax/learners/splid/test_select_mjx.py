"""SELECT's work queue on an MJX task (Push): the lanes' verdicts equal each candidate replayed alone.

The explored episodes and the lone replays both run in a shared episode program (conftest's, of Push with
the library's Cholesky, which test_small_cholesky runs too), so the only program compiled here is SELECT's
own, kept short by that Cholesky."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.fetch import scripted
from splid_jax.learners.imitation.explore import Trajectory
from splid_jax.learners.splid.select import select

H = 4
MOVING = 3  # envs where the noisy scripted pusher explores; the others rest and give no candidate


class ScriptedPolicy:
    """The scripted pusher as SELECT's policy: it solves some relabelled goals, not others."""

    def act(self, _, obs, goal):
        return scripted.push(obs, goal)


def explored(fetch, env) -> Trajectory:
    moving = np.arange(fetch.B) < MOVING
    noise = 0.3 * jax.random.normal(jax.random.PRNGKey(0), (fetch.T, fetch.B, 4)) * moving[:, None]
    s0, _, after = fetch.run(env, noise, w=moving)
    states = jax.tree_util.tree_map(lambda first, rest: jnp.concatenate([first[None], rest[:-1]]), s0, after)
    actions = jnp.clip(noise + moving[:, None] * scripted.push(states.obs, states.desired_goal), -1.0, 1.0)
    return Trajectory(
        states,
        actions,
        jnp.concatenate([s0.achieved_goal[None], after.achieved_goal]),
        jnp.concatenate([s0.invalid[None], after.invalid]),
    )


@pytest.mark.slow
def test_push_queue_verdicts_match_single_replays(fetch):
    env, policy, n = envs.make("push", cholesky="library"), ScriptedPolicy(), fetch.T * fetch.B
    traj = explored(fetch, env)
    cands = jax.jit(lambda tr: select(env, policy, None, tr, H, jnp.int32(H), True, 0.1))(traj)
    valid = np.asarray(cands.valid)
    idx = np.flatnonzero(valid)
    # each valid candidate alone: the scripted pusher restored at its start state, pursuing its goal,
    # hits it within its h steps (policy_reaches' definition), B candidates per run of the program
    starts = jax.tree_util.tree_map(lambda x: x.reshape((n,) + x.shape[2:]), traj.states)
    with_goal = jax.jit(jax.vmap(env.with_goal))
    zeros, alone = np.zeros((fetch.T, fetch.B, 4)), []
    for lo in range(0, len(idx), fetch.B):
        c = np.resize(idx[lo : lo + fetch.B], fetch.B)  # the last batch repeats its candidates
        start = with_goal(jax.tree_util.tree_map(lambda x, c=c: x[c % n], starts), cands.goal[c])
        run = fetch.run(env, zeros, w=1.0, state=start)[2]
        hit = np.asarray(run.success & ~run.invalid)  # [T, B]
        alone += [hit[: c[j] // n + 1, j].any() for j in range(min(fetch.B, len(idx) - lo))]
    alone = np.asarray(alone)
    assert len(idx) > 0 and 0 < alone.sum() < len(idx)
    np.testing.assert_array_equal(np.asarray(cands.accept)[idx], ~alone)
    assert not np.asarray(cands.accept)[~valid].any()
