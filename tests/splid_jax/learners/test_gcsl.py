"""GCSL's relabelling and learner on the point task."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from splid_jax.common.errors import InvalidConfig
from splid_jax.common.evaluation import evaluate
from splid_jax.common.networks import make_policy
from splid_jax.config import TrainConfig
from splid_jax.learners import gcsl
from splid_jax.learners.splid.trainer import Trainer
from tests.helpers import explore

T, N = 12, 5


@pytest.fixture(scope="module")
def traj():
    env = envs.make("point", max_episode_steps=T)
    policy = make_policy(env.obs_size, env.goal_size, env.action_size, (8,), normalise=False)
    # one compiled program (op by op, each primitive would compile on its own)
    episodes = jax.jit(lambda k0, k1: explore(env, policy, policy.init(k0), k1, N, jnp.float32(1.0)))
    return env, episodes(jax.random.PRNGKey(0), jax.random.PRNGKey(1))


def relabelled(env, tr, mode, seed):
    return jax.jit(gcsl.relabel, static_argnums=(0, 2))(env, tr.seen(), mode, jax.random.PRNGKey(seed))


def test_final_pairs_every_step_with_the_episodes_last_achieved_goal(traj):
    env, tr = traj
    c = relabelled(env, tr, "final", 0)
    np.testing.assert_array_equal(c.goal.reshape(T, N, -1), np.broadcast_to(tr.achieved[T], (T, N, 2)))
    np.testing.assert_array_equal(c.action.reshape(T, N, -1), tr.actions)
    assert bool(c.accept.all()) and int(c.replay_steps) == 0


def test_future_goals_come_uniformly_from_later_steps_of_the_same_episode(traj):
    env, tr = traj
    achieved = np.asarray(tr.achieved)
    later = []
    for seed in range(40):
        goal = np.asarray(relabelled(env, tr, "future", seed).goal).reshape(T, N, 2)
        for t in range(T):
            for n in range(N):
                (match,) = np.nonzero((achieved[:, n] == goal[t, n]).all(-1))
                assert match.max() > t  # a strictly later achieved goal of episode n
                later.append((t, match.max()))
    # from t = 0 every later step 1..T is drawn about equally often (40 x N draws over 12 steps)
    counts = np.bincount([s for t, s in later if t == 0], minlength=T + 1)[1:]
    assert counts.min() > 0 and counts.max() < 4 * counts.mean()
    assert all(s == T for t, s in later if t == T - 1)


def test_pchid_horizon_grows_by_one_every_pchid_every_iterations_up_to_h():
    env = envs.make("point")
    small = dict(env="point", iterations=40, horizon=4, hidden=(8,))
    pchid = Trainer(env, TrainConfig(**small, algo="pchid", pchid_every=3))
    assert [int(pchid.horizon_at(jnp.int32(i), pchid.hyper())) for i in range(14)] == [
        1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 4, 4
    ]  # fmt: skip
    resolved = Trainer(env, TrainConfig(**small, algo="pchid"))  # 0: H reached half-way, 40 // (2 * 4) = 5
    assert [int(resolved.horizon_at(jnp.int32(i), resolved.hyper())) for i in (0, 4, 5, 19, 20, 39)] == [
        1, 1, 2, 4, 4, 4
    ]  # fmt: skip
    for algo in ("splid", "gcsl"):  # the full horizon from the start
        fixed = Trainer(env, TrainConfig(**small, algo=algo))
        assert [int(fixed.horizon_at(jnp.int32(i), fixed.hyper())) for i in (0, 7, 39)] == [4, 4, 4]


def test_splid_horizon_falls_to_horizon_end_with_the_noise_and_pchid_refuses_it():
    env = envs.make("point")
    small = dict(env="point", iterations=40, horizon=12, hidden=(8,), sigma_end=0.5, sigma_anneal=5)
    falling = Trainer(env, TrainConfig(**small, horizon_end=8))
    assert [int(falling.horizon_at(jnp.int32(i), falling.hyper())) for i in range(7)] == [12, 11, 10, 9, 8, 8, 8]
    sigmas = [float(falling.sigma_at(jnp.int32(i), falling.hyper())) for i in (0, 4)]
    assert sigmas == pytest.approx([1.0, 0.5])  # the horizon's schedule is the noise's
    with pytest.raises(InvalidConfig, match="horizon_end"):
        Trainer(env, TrainConfig(**small, algo="pchid", horizon_end=8))


def test_gcsl_and_pchid_learn_on_the_point_task():
    cfg = dict(env="point", num_envs=16, iterations=20, eval_every=10, bc_steps=50, batch_size=128, eval_episodes=128)
    env = envs.make("point")
    out = {}
    for algo in ("gcsl", "pchid"):
        trainer = Trainer(env, TrainConfig(**cfg, algo=algo))
        chunk = jax.jit(trainer.chunk)
        state = trainer.init(jax.random.PRNGKey(0))
        first, metrics = chunk(state, trainer.hyper())
        _, metrics = chunk(first, trainer.hyper())
        out[algo] = float(metrics["eval_success"])
        if algo == "pchid":  # the horizon grows 1, 2, ...: iterations // (2 H) = 1 per step here
            assert trainer.pchid_every == 1 and int(metrics["horizon"]) == min(8, 20)
    untrained = float(evaluate(env, trainer.policy, state.policy, jax.random.PRNGKey(5), 128)["eval_success"])
    for algo, success in out.items():
        assert success > untrained + 0.2, (algo, success, untrained)
