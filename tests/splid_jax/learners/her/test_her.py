"""DDPG + HER on the point task: future relabelling, rewards and targets as Baselines computes them,
one compilation, determinism, and learning well above a random policy."""

import dataclasses
import functools

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import envs
from envs.base import GoalEnv
from envs.point_fourrooms import PointFourRooms
from splid_jax.common.errors import InvalidConfig
from splid_jax.config import TrainConfig
from splid_jax.learners.her import episode_buffer
from splid_jax.learners.her import learner as her_mod
from splid_jax.learners.her.config import BASELINES, HerConfig
from splid_jax.learners.her.learner import HER
from tests.helpers import random_policy_success, with_counted_jit

CFG = dict(env="point", num_envs=16, iterations=150, eval_every=25, eval_episodes=256)
HER_CFG = dict(BASELINES, hidden=(64, 64, 64), buffer_transitions=100_000, batch_size=256)
CHUNKS = 6  # 150 cycles, 2,400 episodes
# The suite compiles at LLVM's level 0 (conftest.CPU_COMPILE_FLAGS), right for programs run once or twice (the
# mrl preset's chunk below); this chunk runs 9 times here, 2.5x faster at level 2 for 3 s more compiling (about 20 s
# less in all). Every run the tests compare comes from one compiled chunk.
RUN_FAST = {"xla_backend_optimization_level": 2}


@pytest.fixture(scope="module")
def her():
    return with_counted_jit(HER(envs.make("point"), TrainConfig(**CFG), HerConfig(**HER_CFG)), RUN_FAST)


def run_chunks(her, seed, chunks):
    state, states, out = her.init(jax.random.PRNGKey(seed)), [], []
    for _ in range(chunks):
        state, metrics = her.jitted(state, her.hyper())
        states.append(state)
        out.append({k: float(v) for k, v in jax.device_get(metrics).items()})
    return states, out


@pytest.fixture(scope="module")
def learned(her):
    return run_chunks(her, 0, CHUNKS)


@pytest.fixture(scope="module")
def other_seed(her):
    """One chunk from seed 1, run once: the retrace check and the seed check both read it."""
    return run_chunks(her, 1, 1)


sample = jax.jit(episode_buffer.sample_transitions, static_argnums=(2, 3, 4, 5))


def coded_buffer(episodes=8, filled=6, T=5):
    """Episodes whose observations and achieved goals are their own (episode, step) and whose goal is
    (episode, -1), so every sampled field says where it came from."""
    e = jnp.arange(episodes, dtype=jnp.float32)[:, None] * jnp.ones((1, T + 1))
    t = jnp.ones((episodes, 1)) * jnp.arange(T + 1, dtype=jnp.float32)[None]
    coded = jnp.stack([e, t], axis=-1)
    buf = episode_buffer.buffer_init(episodes, T, 2, 2, 2)
    return buf.replace(
        obs=coded,
        achieved=coded,
        goal=jnp.stack([e[:, 0], -jnp.ones(episodes)], axis=-1),
        actions=coded[:, :T],
        size=jnp.int32(filled),
    )


def test_future_relabelling_draws_later_achieved_goals_of_the_same_episode():
    env, buf, T, n = PointFourRooms(), coded_buffer(), 5, 20_000
    future_p = HerConfig(replay_k=4, actual_k=0).future_p
    tr = jax.device_get(sample(buf, jax.random.PRNGKey(0), n, future_p, env.reward_of))
    ep, t = tr.episode, tr.t
    assert ep.min() == 0 and ep.max() == 5  # only filled slots
    assert t.min() == 0 and t.max() == T - 1
    np.testing.assert_array_equal(tr.obs, np.stack([ep, t], -1))
    np.testing.assert_array_equal(tr.next_obs, np.stack([ep, t + 1], -1))
    rel = tr.relabelled
    assert abs(rel.mean() - 0.8) < 0.015, rel.mean()
    # Relabelled: the achieved goal of a later step (t + 1 .. T) of the same episode; else the episode's goal.
    np.testing.assert_array_equal(tr.goal[rel], np.stack([ep, tr.future], -1)[rel])
    np.testing.assert_array_equal(tr.goal[~rel], np.stack([ep, -np.ones(n)], -1)[~rel])
    assert (tr.future >= t + 1).all() and (tr.future <= T).all()
    np.testing.assert_array_equal(np.unique(tr.future[t == 0]), np.arange(1, T + 1))  # every later step
    none = sample(buf, jax.random.PRNGKey(1), 1000, HerConfig(replay_k=0, actual_k=0).future_p, env.reward_of)
    assert not np.asarray(none.relabelled).any()


def test_relabelled_rewards_are_the_tasks_reward_of_the_next_achieved_goal():
    env, buf = PointFourRooms(), coded_buffer()
    tr = jax.device_get(sample(buf, jax.random.PRNGKey(2), 4000, 0.8, env.reward_of))
    expected = env.reward_of(jnp.stack([tr.episode, tr.t + 1], -1).astype(jnp.float32), tr.goal)
    np.testing.assert_array_equal(tr.reward, expected)
    # Goals one step ahead are within the radius, later ones are not: both rewards occur.
    assert set(np.unique(tr.reward[tr.relabelled])) == {0.0, 1.0}
    np.testing.assert_array_equal(tr.reward[tr.relabelled], (tr.future[tr.relabelled] <= tr.t[tr.relabelled] + 2))


@dataclasses.dataclass(frozen=True)
class FetchRewardPoint(PointFourRooms):
    """The point task under the Fetch reward convention: -1 unless successful, then 0."""

    reward_of = GoalEnv.reward_of


def test_target_is_clipped_to_the_returns_the_sparse_reward_allows():
    cfg = TrainConfig(**CFG, algo="her")
    assert HER(FetchRewardPoint(), cfg).target_range == pytest.approx((-50.0, 0.0))  # Baselines' range
    assert HER(PointFourRooms(), cfg).target_range == pytest.approx((0.0, 50.0))  # 1 on the goal, else 0
    r = jnp.array([-1.0, -1.0, 0.0, 0.0])
    q = jnp.array([-80.0, -10.0, 5.0, -3.0])
    np.testing.assert_allclose(her_mod.td_target(r, q, 0.98, -50.0, 0.0), [-50.0, -10.8, 0.0, -2.94], rtol=1e-6)


def test_updates_drawn_at_once_are_the_updates_drawn_one_at_a_time(her, learned):
    # a cycle's batches and TD targets come before its scan of steps: as if each step drew its own batch from
    # its own key and took its targets from the (fixed) target networks
    state = learned[0][0]
    key = jax.random.PRNGKey(5)
    at_once, losses = jax.jit(her.updates)(state, key)
    h, cfg = state, her.her

    @jax.jit
    def one(h, k):
        tr = episode_buffer.sample_transitions(h.buffer, k, cfg.batch_size, cfg.future_p, her.env.reward_of)
        return her.train_step(h, (tr, her.td_targets(h, tr)))

    steps = []
    for k in jax.random.split(key, cfg.n_batches):
        h, step_losses = one(h, k)
        steps.append(float(step_losses["critic_loss"]))
    np.testing.assert_allclose(losses["critic_loss"], steps, rtol=1e-5)
    for a, b in zip(jax.tree_util.tree_leaves(at_once), jax.tree_util.tree_leaves(h), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6)


def test_buffer_keeps_only_valid_episodes_first_in_first_out():
    buf = episode_buffer.buffer_init(3, 2, 1, 1, 1)
    new = episode_buffer.buffer_init(4, 2, 1, 1, 1)
    new = new.replace(goal=jnp.arange(1.0, 5.0)[:, None])
    buf = episode_buffer.buffer_insert(buf, new, jnp.array([True, False, True, True]))
    assert int(buf.size) == 3 and int(buf.ptr) == 0
    np.testing.assert_array_equal(buf.goal[:, 0], [1.0, 3.0, 4.0])
    buf = episode_buffer.buffer_insert(buf, new, jnp.array([False, True, False, False]))
    np.testing.assert_array_equal(buf.goal[:, 0], [2.0, 3.0, 4.0])
    assert int(buf.size) == 3 and int(buf.ptr) == 1


def test_exploration_without_noise_takes_the_actors_action():
    env, cfg = PointFourRooms(max_episode_steps=5), TrainConfig(**{**CFG, "num_envs": 4})
    quiet = HER(env, cfg, HerConfig(**{**HER_CFG, "random_eps": 0.0, "noise_eps": 0.0}))
    state = quiet.init(jax.random.PRNGKey(3))
    episodes, valid, _ = jax.jit(quiet.explore)(state.policy, jax.random.PRNGKey(4))
    assert bool(valid.all())
    goals = jnp.broadcast_to(episodes.goal[:, None], (4, 5, 2))
    np.testing.assert_allclose(episodes.actions, quiet.policy.act(state.policy, episodes.obs[:, :-1], goals), atol=1e-6)
    assert float(jnp.abs(episodes.actions).max()) < 1.0  # tanh output
    np.testing.assert_array_equal(episodes.obs, episodes.achieved)  # the point's observation is its position


def test_chunk_compiles_once_and_is_not_retraced(her, learned, other_seed):
    assert her.traces == 1  # after seed 0's chunks and seed 1's (other_seed)


def test_her_learns_well_above_a_random_policy(her, learned):
    _, metrics = learned
    baseline = random_policy_success(her.env)
    last = metrics[-1]
    # Seeds 0-3 reach 0.55-0.60 (either measure) against a random policy's 0.21.
    assert last["eval_success"] > baseline + 0.25, (last, baseline)
    assert last["eval_success_final"] > baseline + 0.25, (last, baseline)
    assert last["eval_success"] > metrics[0]["eval_success"] + 0.2
    assert last["finite"] == 1.0 and last["buffer_size"] == min(CHUNKS * 25 * 16, her.capacity)
    assert "select_steps" not in last
    assert her.counters(150, 0) == {"iteration": 150, "episodes": 2400, "env_steps": 120_000, "select_steps": 0}


def test_same_seed_same_metrics_different_seed_different(her, learned, other_seed):
    states, metrics = learned
    states_again, metrics_again = run_chunks(her, 0, 1)
    assert metrics_again[0] == metrics[0]
    for a, b in zip(jax.tree_util.tree_leaves(states[0]), jax.tree_util.tree_leaves(states_again[0]), strict=True):
        np.testing.assert_array_equal(a, b)
    _, metrics1 = other_seed
    assert metrics1[0] != metrics[0]


def test_config_errors_name_the_field():
    with pytest.raises(InvalidConfig, match="her.polyak"):
        HerConfig(polyak=1.5)
    with pytest.raises(InvalidConfig, match="her.buffer_transitions"):
        HER(PointFourRooms(), TrainConfig(**CFG), HerConfig(buffer_transitions=10))
    # settings that leave an iteration without a gradient step
    with pytest.raises(InvalidConfig, match="her.n_batches"):
        HerConfig(update_every=0, n_batches=0)
    with pytest.raises(InvalidConfig, match="her.update_every"):
        HER(PointFourRooms(), TrainConfig(**{**CFG, "num_envs": 2}), HerConfig(update_every=101))
    assert HER(PointFourRooms(), TrainConfig(**{**CFG, "num_envs": 2}), HerConfig(update_every=100)).n_updates == 1


def test_futureactual_mix_draws_a_fifth_real_two_fifths_future_two_fifths_stored_goals():
    env, buf, n = PointFourRooms(), coded_buffer(), 20_000
    mix = HerConfig(replay_k=2, actual_k=2)
    tr = jax.device_get(sample(buf, jax.random.PRNGKey(6), n, mix.future_p, env.reward_of, mix.actual_p))
    real = ~tr.relabelled & ~tr.actual
    for share, expected in ((real, 0.2), (tr.relabelled, 0.4), (tr.actual, 0.4)):
        assert abs(share.mean() - expected) < 0.015, (share.mean(), expected)
    assert not (tr.relabelled & tr.actual).any()
    # "actual": the desired goal of a uniformly drawn filled slot, any episode's, not only the sampled one's
    np.testing.assert_array_equal(tr.goal[tr.actual], np.stack([tr.other, -np.ones(n)], -1)[tr.actual])
    assert set(np.unique(tr.other[tr.actual])) == set(range(6))
    assert (tr.other[tr.actual] != tr.episode[tr.actual]).mean() > 0.7
    np.testing.assert_array_equal(tr.goal[real], np.stack([tr.episode, -np.ones(n)], -1)[real])
    # before the warm-up of stored transitions every goal is a future one (mrl's future_warm_up) ...
    early = jax.device_get(sample(buf, jax.random.PRNGKey(6), n, mix.future_p, env.reward_of, mix.actual_p, False))
    assert not early.actual.any() and early.relabelled.all()
    # ... while "future" alone (Baselines' future_4) keeps its real fifth whatever the flag
    base = HerConfig(replay_k=4, actual_k=0)
    plain = jax.device_get(sample(buf, jax.random.PRNGKey(6), n, base.future_p, env.reward_of, base.actual_p, False))
    assert abs(plain.relabelled.mean() - 0.8) < 0.015


def _her(num_envs=4, **her):
    return HER(PointFourRooms(), TrainConfig(**{**CFG, "num_envs": num_envs}), HerConfig(**her))


def test_gradient_steps_per_collected_transition():
    key = jax.random.PRNGKey(0)
    for update_every, expected in ((2, 100), (5, 40), (0, 7)):  # 4 envs x 50 steps; 0: n_batches per iteration
        her = _her(update_every=update_every, n_batches=7, hidden=(8,), batch_size=4, buffer_transitions=500)
        _, losses = jax.eval_shape(her.updates, jax.eval_shape(her.init, key), key)
        assert her.n_updates == expected and losses["critic_loss"].shape == (expected,)


def test_layer_norm_in_both_networks_where_configured():
    def norms(params):
        return [k for k in jax.tree_util.tree_flatten_with_path(params)[0] if "LayerNorm" in jax.tree_util.keystr(k[0])]

    for layer_norm, count in ((True, 2 * 2 * 3), (False, 0)):  # scale and bias of 3 hidden layers, 2 networks
        her = _her(layer_norm=layer_norm, hidden=(8, 8, 8), buffer_transitions=500)
        state = jax.eval_shape(her.init, jax.random.PRNGKey(0))
        assert len(norms(state.policy.params)) + len(norms(state.critic)) == count


def test_bfloat16_computes_the_hidden_layers_in_bfloat16_and_keeps_parameters_and_outputs_float32():
    def dtypes(her):  # traced for their types alone (jax.eval_shape): nothing is compiled
        state = jax.eval_shape(her.init, jax.random.PRNGKey(0))
        x = jnp.ones((2, state.critic["params"]["Dense_0"]["kernel"].shape[0]))
        mlp = her.critic.clone(parent=None)
        _, seen = jax.eval_shape(lambda c, x: mlp.apply(c, x, capture_intermediates=True), state.critic, x)
        inner = [v.dtype for k, v in jax.tree_util.tree_flatten_with_path(seen)[0] if "Dense_0" in str(k)]
        out = jax.eval_shape(mlp.apply, state.critic, x)
        params = {leaf.dtype for leaf in jax.tree_util.tree_leaves((state.critic, state.policy.params))}
        return inner, out.dtype, params

    inner, out, params = dtypes(_her(compute_dtype="bfloat16", hidden=(8, 8), buffer_transitions=500))
    assert inner == [jnp.bfloat16] and out == jnp.float32 and params == {jnp.dtype(jnp.float32)}
    inner, out, _ = dtypes(_her(hidden=(8, 8), buffer_transitions=500))
    assert inner == [jnp.float32] and out == jnp.float32
    with pytest.raises(InvalidConfig, match="compute_dtype"):
        HerConfig(compute_dtype="float16")


@functools.cache
def blocked_her():
    """A HER whose targets move every 3 of its 6 gradient steps, its start, the start with one batch of explored
    episodes stored (warm) and with none (cold), and its jitted updates: one compile for both tests reading them."""
    small = dict(hidden=(8,), batch_size=8, buffer_transitions=500)
    her = _her(update_every=0, n_batches=6, target_every=3, warm_up=0, **small)
    state = jax.jit(her.init)(jax.random.PRNGKey(1))  # compiled whole here and below: op by op is slower
    episodes, valid, _ = jax.jit(her.explore)(state.policy, jax.random.PRNGKey(2))
    insert = jax.jit(episode_buffer.buffer_insert)
    cold = state.replace(buffer=insert(state.buffer, episodes, valid[:0].any() & valid))
    warm = state.replace(buffer=insert(state.buffer, episodes, valid))
    return her, cold, warm, jax.jit(her.updates)


def test_targets_move_every_target_every_steps_only_once_warm():
    _, cold, warm, updates = blocked_her()
    for start, moves in ((cold, False), (warm, True)):
        # targets apart from the online critic, so that a move shows even where the critic did not learn
        start = start.replace(target_critic=jax.tree_util.tree_map(lambda x: x + 0.1, start.target_critic))
        after, _ = updates(start, jax.random.PRNGKey(3))
        leaf = lambda s: jax.tree_util.tree_leaves(s.target_critic)[-1]  # noqa: E731
        assert (not np.array_equal(leaf(after), leaf(start))) == moves
        assert (
            not np.array_equal(after.critic["params"]["Dense_0"]["kernel"], start.critic["params"]["Dense_0"]["kernel"])
        ) == moves


def test_blocks_of_target_every_steps_equal_the_steps_one_at_a_time():
    # each block of target_every steps takes its TD targets in one pass: as if every step computed its own
    # from target networks that move after every target_every-th step
    her, _, state, updates = blocked_her()
    key = jax.random.PRNGKey(3)
    blocked, losses = updates(state, key)
    batches = jax.jit(lambda s, k: her.draw(s, k, her.n_updates))(state, key)
    step = jax.jit(lambda h, tr: her.train_step(h, (tr, her.td_targets(h, tr))))
    move_targets = jax.jit(her._moved_targets)
    h, critic_losses = state, []
    for i in range(her.n_updates):
        h, step_losses = step(h, jax.tree_util.tree_map(lambda x, i=i: x[i], batches))
        critic_losses.append(float(step_losses["critic_loss"]))
        if (i + 1) % 3 == 0:
            moved = move_targets(h)
            h = h.replace(target_actor=moved.target_actor, target_critic=moved.target_critic)
    np.testing.assert_allclose(losses["critic_loss"], critic_losses, rtol=1e-5)
    for a, b in zip(jax.tree_util.tree_leaves(blocked), jax.tree_util.tree_leaves(h), strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-5, atol=1e-6)


def test_the_mrl_preset_learns_the_point_task_within_400_episodes():
    """mrl's settings scaled to the CPU (narrower nets, batches of 64, a step per 8 transitions, warm-ups
    shortened in proportion). Without its gradient steps the policy would stay at its initial one, which rarely
    reaches the goal."""
    small = dict(hidden=(64, 64), batch_size=64, buffer_transitions=100_000, update_every=8)
    small.update(random_transitions=2_000, warm_up=1_000, actual_warm_up=5_000)
    cfg = TrainConfig(**{**CFG, "num_envs": 8, "iterations": 50, "eval_every": 25})
    her = HER(envs.make("point"), cfg, HerConfig(**small))
    assert her.n_updates == 50
    state, chunk = her.init(jax.random.PRNGKey(0)), jax.jit(her.chunk)  # run twice: the suite's level 0
    for _ in range(2):
        state, metrics = chunk(state, her.hyper())
    baseline = random_policy_success(her.env)
    # seeds 0 and 1 reach 0.68 and 0.61 against a random policy's 0.20
    assert float(metrics["eval_success_final"]) > baseline + 0.3, (metrics, baseline)
    assert float(metrics["critic_loss"]) > 0 and int(metrics["buffer_size"]) == 400
