"""OpenAI-ES through evosax on the point task: it climbs the return, compiles once, is
deterministic for a seed, and learns."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from jax.flatten_util import ravel_pytree

import envs
from splid_jax.common.errors import InvalidConfig
from splid_jax.common.evaluation import evaluate
from splid_jax.config import TrainConfig
from splid_jax.learners.es.config import EsConfig
from splid_jax.learners.es.learner import ES
from tests.helpers import with_counted_jit

CFG = dict(env="point", hidden=(32, 32), iterations=80, eval_every=10, eval_episodes=256)
ES_CFG = dict(population=128, sigma=0.05)
CHUNKS = 8


@pytest.fixture(scope="module")
def es():
    return with_counted_jit(ES(envs.make("point"), TrainConfig(**CFG), EsConfig(**ES_CFG)))


def run_chunks(es, seed, chunks):
    state, out = es.init(jax.random.PRNGKey(seed)), []
    for _ in range(chunks):
        state, metrics = es.jitted(state, es.hyper())
        out.append({k: float(v) for k, v in jax.device_get(metrics).items()})
    return state, out


@pytest.fixture(scope="module")
def learned(es):
    return run_chunks(es, 0, CHUNKS)


@pytest.fixture(scope="module")
def other_seed(es):
    """One chunk from seed 1, run once: the retrace check and the seed check both read it."""
    return run_chunks(es, 1, 1)


class Toy(ES):
    """ES whose members are scored without the simulator: return = <theta, direction>, and the members
    scoring above zero are flagged invalid when ``poison`` is set."""

    direction = None
    poison = False
    diverged = False  # every member's episodes went NaN

    def episode_returns(self, pstate, members, key):
        flat = jax.vmap(lambda p: ravel_pytree(p)[0])(members)
        ret = flat @ self.direction if self.direction is not None else jnp.zeros(flat.shape[0])
        invalid = ((ret > 0) & self.poison) | self.diverged
        return ret, jnp.zeros_like(invalid), invalid


def toy_search(generations=20, **es_cfg):
    toy = Toy(envs.make("point"), TrainConfig(**{**CFG, "hidden": (2,)}), EsConfig(**{**ES_CFG, **es_cfg}))
    state = toy.init(jax.random.PRNGKey(0))
    toy.direction = jax.random.normal(jax.random.PRNGKey(1), state.search.mean.shape)
    return toy, state.search.mean, state


def run_generations(toy, state, generations=20):
    state, _ = jax.jit(lambda s: jax.lax.scan(lambda t, _: toy.generation(t), s, None, length=generations))(state)
    return state.search.mean


def cosine(a, b):
    return float(jnp.dot(a, b) / (jnp.linalg.norm(a) * jnp.linalg.norm(b)))


def test_the_mean_moves_toward_higher_return():
    toy, mean0, state = toy_search()
    moved = run_generations(toy, state) - mean0
    assert cosine(moved, toy.direction) > 0.8


def test_a_member_whose_episode_went_nan_ranks_last():
    toy, mean0, state = toy_search()
    toy.poison = True  # every member with a positive return is invalid: the search must turn away
    moved = run_generations(toy, state) - mean0
    assert cosine(moved, toy.direction) < -0.5


@pytest.mark.parametrize("diverged", [False, True])
def test_a_generation_whose_every_member_went_nan_is_divergence(diverged):
    toy, _, state = toy_search()
    toy.poison, toy.diverged = True, diverged  # some members invalid, or all of them
    _, per_gen = jax.jit(toy.generation)(state)
    _, finite = toy.watched(state, jax.tree.map(lambda x: x[None], per_gen))
    assert bool(finite.all()) != diverged


def test_weight_decay_shrinks_the_parameters_when_returns_tie():
    toy, mean0, state = toy_search(weight_decay=0.1)
    toy.direction = None  # every member scores 0: only the penalty ranks them
    assert float(jnp.linalg.norm(run_generations(toy, state))) < float(jnp.linalg.norm(mean0)) - 0.1


def test_mirrored_members_play_the_same_episodes(es):
    state = es.init(jax.random.PRNGKey(0))
    members, _ = es.strategy.ask(jax.random.PRNGKey(1), state.search, es.es_params)
    flat = jax.vmap(lambda p: ravel_pytree(p)[0])(members)
    half = ES_CFG["population"] // 2
    np.testing.assert_allclose(
        (flat[:half] + flat[half:]) / 2, np.broadcast_to(state.search.mean, (half, flat.shape[1])), atol=1e-6
    )  # evosax's layout
    two = ES(es.env, es.cfg, EsConfig(**ES_CFG, episodes_per_member=2))
    keys = np.asarray(two.episode_keys(jax.random.PRNGKey(2))).reshape(2, half * 2, -1)  # [mirror, member x episode]
    np.testing.assert_array_equal(keys[0], keys[1])
    assert len(np.unique(keys[0], axis=0)) == half * 2
    unpaired = ES(es.env, es.cfg, EsConfig(**ES_CFG, paired_episodes=False))
    assert len(np.unique(np.asarray(unpaired.episode_keys(jax.random.PRNGKey(2))), axis=0)) == half * 2


def test_chunk_compiles_once_and_is_not_retraced(es, learned, other_seed):
    assert es.traces == 1  # after seed 0's chunks and seed 1's (other_seed)


def test_same_seed_same_metrics_different_seed_different(es, learned, other_seed):
    state0, metrics0 = learned
    state_again, metrics_again = run_chunks(es, 0, CHUNKS)
    assert metrics_again == metrics0
    np.testing.assert_array_equal(state0.search.mean, state_again.search.mean)
    _, metrics1 = other_seed
    assert metrics1[0] != metrics0[0]


def test_es_learns_well_above_its_initial_policy(es, learned):
    state, metrics = learned
    start = es.init(jax.random.PRNGKey(0))
    initial = evaluate(es.env, es.policy, start.policy, jax.random.PRNGKey(7), CFG["eval_episodes"])
    final = metrics[-1]
    assert final["eval_success"] > float(initial["eval_success"]) + 0.2, (final, initial)
    assert final["eval_return"] > 2 * float(initial["eval_return"]) + 1, (final, initial)
    assert final["finite"] == 1.0 and final["explore_success"] > 0
    assert final["fitness_max"] >= final["fitness_mean"]
    # the acting policy is the search mean
    np.testing.assert_array_equal(ravel_pytree(state.policy.params)[0], state.search.mean)


def test_counters_count_every_members_episodes(es):
    c = es.counters(7, 0)
    assert c == {"iteration": 7, "episodes": 7 * 128, "env_steps": 7 * 128 * 50, "select_steps": 0}
    two = ES(es.env, es.cfg, EsConfig(**ES_CFG, episodes_per_member=2))
    assert two.counters(7, 0)["episodes"] == 7 * 128 * 2


@pytest.mark.parametrize(
    "field, value",
    [
        ("population", 7),  # odd with antithetic sampling
        ("population", 1),
        ("sigma", 0.0),
        ("learning_rate", -1.0),
        ("fitness_shaping", "rank"),
        ("episodes_per_member", 0),
        ("weight_decay", -0.1),
    ],
)
def test_config_names_the_bad_field(field, value):
    with pytest.raises(InvalidConfig, match=rf"es\.{field}="):
        EsConfig(**{field: value})
