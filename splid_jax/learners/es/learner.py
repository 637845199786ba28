"""OpenAI-ES (Salimans et al. 2017) as an ``learners.base.Algorithm``: evosax's ``Open_ES`` searches the
deterministic policy's parameters; each member of a population plays whole episodes and its
fitness is the episode return under the task's sparse reward.

One iteration is one generation: ask a population, roll every member from fresh resets (all members
and episodes as one batch of envs), tell the returns. ``cfg.sigma`` and ``cfg.learning_rate`` are
SPLID's and unused here; ``TrainConfig`` sets ``cfg.num_envs`` to the episodes per generation."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import optax
from evosax.algorithms import Open_ES
from evosax.core.fitness_shaping import (
    add_weight_decay,
    centered_rank_fitness_shaping_fn,
    identity_fitness_shaping_fn,
    standardize_fitness_shaping_fn,
)
from flax import struct

from envs.base import GoalEnv, State, step_batch
from splid_jax.common.networks import PolicyState, make_policy
from splid_jax.config import TrainConfig
from splid_jax.learners.base import Chunked
from splid_jax.learners.es.config import EsConfig

# Fitness shaping by name (evosax's functions): ranks make the update invariant to the return's scale.
SHAPING = {
    "centered_rank": centered_rank_fitness_shaping_fn,
    "standardize": standardize_fitness_shaping_fn,
    "raw": identity_fitness_shaping_fn,
}


@struct.dataclass
class EsState:
    search: struct.PyTreeNode  # evosax's Open_ES state: flat mean, Adam state, generation counter
    policy: PolicyState  # the search mean as the acting policy (eval, checkpoints' rollouts)
    key: jax.Array
    iteration: jax.Array  # [] int32, completed generations


class ES(Chunked):
    """OpenAI-ES on the deterministic policy (``Policy.act``) without an input normaliser: a moving one
    would change every member's function between generations."""

    name = "es"

    def __init__(self, env: GoalEnv, cfg: TrainConfig, es: EsConfig | None = None):
        es = cfg.learner_config() if es is None else es
        self.env, self.cfg, self.es = env, cfg, es
        self.policy = make_policy(env.obs_size, env.goal_size, env.action_size, cfg.hidden, normalise=False)
        template = self.policy.init(jax.random.PRNGKey(0)).params  # shapes only, for evosax's ravel
        shaping = SHAPING[es.fitness_shaping]
        if es.weight_decay > 0:
            shaping = add_weight_decay(shaping, es.weight_decay)  # adds to the minimised fitness
        self.strategy = Open_ES(
            population_size=es.population,
            solution=template,
            use_antithetic_sampling=es.antithetic,
            optimizer=optax.adam(es.learning_rate),
            std_schedule=lambda _: jnp.float32(es.sigma),  # strongly typed, as the state it sets
            fitness_shaping_fn=shaping,
        )
        self.es_params = self.strategy.default_params

    def hyper(self, cfg: TrainConfig | None = None) -> dict:
        return {}  # nothing traced: a sweep's members differ only by seed

    def init(self, key: jax.Array) -> EsState:
        k_policy, k_search, k_run = jax.random.split(key, 3)
        pstate = self.policy.init(k_policy)
        search = self.strategy.init(k_search, pstate.params, self.es_params)
        # evosax starts some leaves weakly typed (inf, nan fills); strong types keep the chunk's
        # input and output types equal, so it compiles once.
        search = jax.tree_util.tree_map(lambda x: jnp.asarray(x, x.dtype), search)
        return EsState(policy=pstate, search=search, key=k_run, iteration=jnp.int32(0))

    def episode_keys(self, key: jax.Array) -> jax.Array:
        """Reset keys of the P x E episodes, member-major. With paired episodes a member and its mirror
        (evosax puts it P/2 later) share theirs, so their returns differ by the perturbation's sign only."""
        pop, per = self.es.population, self.es.episodes_per_member
        if not (self.es.antithetic and self.es.paired_episodes):
            return jax.random.split(key, pop * per)
        half = jnp.arange(pop // 2 * per).reshape(pop // 2, per)
        return jax.random.split(key, pop // 2 * per)[jnp.tile(half, (2, 1)).reshape(-1)]

    def episode_returns(
        self, pstate: PolicyState, members: dict, key: jax.Array
    ) -> tuple[jax.Array, jax.Array, jax.Array]:
        """Each member's mean return, whether any of its episodes succeeded, and whether any went NaN:
        [P] each. All P x E episodes step as one batch of envs from fresh resets."""
        env, pop, per = self.env, self.es.population, self.es.episodes_per_member

        def act(params, obs, goal):  # one member's E episodes
            return jnp.clip(self.policy.mean(pstate, obs, goal, params=params), -1.0, 1.0)

        def one_step(state: State, _):
            obs = state.obs.reshape(pop, per, -1)
            goal = state.desired_goal.reshape(pop, per, -1)
            action = jax.vmap(act)(members, obs, goal).reshape(pop * per, -1)
            nxt = step_batch(env, state, action)
            return nxt, (nxt.reward, nxt.success)

        start = jax.vmap(env.reset)(self.episode_keys(key))
        final, (reward, success) = jax.lax.scan(one_step, start, None, length=env.episode_length)
        ret = jnp.sum(reward, axis=0).reshape(pop, per).mean(axis=1)
        hit = jnp.any(success, axis=0).reshape(pop, per).any(axis=1)
        invalid = final.invalid.reshape(pop, per).any(axis=1)
        return ret, hit, invalid

    def generation(self, ts: EsState) -> tuple[EsState, dict]:
        key, k_ask, k_episodes, k_tell = jax.random.split(ts.key, 4)
        members, search = self.strategy.ask(k_ask, ts.search, self.es_params)
        ret, hit, invalid = self.episode_returns(ts.policy, members, k_episodes)
        # A member whose episode went NaN ranks with the worst valid one; evosax minimises, so negate.
        worst = jnp.min(jnp.where(invalid, jnp.inf, ret))
        fitness = -jnp.where(invalid, jnp.where(jnp.isfinite(worst), worst, 0.0), ret)
        search, _ = self.strategy.tell(k_tell, members, fitness, search, self.es_params)
        pstate = ts.policy.replace(params=self.strategy.get_mean(search))
        metrics = {
            "fitness_mean": jnp.mean(ret),
            "fitness_max": jnp.max(jnp.where(invalid, -jnp.inf, ret)),
            "explore_success": jnp.mean(hit),
            "explore_invalid": jnp.mean(invalid),
        }
        return EsState(search=search, policy=pstate, key=key, iteration=ts.iteration + 1), metrics

    def iteration(self, ts: EsState, hyper: dict) -> tuple[EsState, dict]:
        return self.generation(ts)

    def chunk_metrics(self, ts: EsState, hyper: dict, per_gen: dict) -> dict:
        return dict(
            fitness_mean=jnp.mean(per_gen["fitness_mean"]),  # mean member return over the chunk
            fitness_max=jnp.max(per_gen["fitness_max"]),  # best member return in the chunk
            explore_success=jnp.mean(per_gen["explore_success"]),
            explore_invalid=jnp.mean(per_gen["explore_invalid"]),
        )

    def watched(self, ts: EsState, per_gen: dict) -> tuple:
        """The search mean, and per generation whether its returns were finite and any member's episodes
        stayed valid (none did: a mean so far off that the whole population's physics went NaN)."""
        return ts.search.mean, jnp.isfinite(per_gen["fitness_mean"]) & jnp.isfinite(per_gen["fitness_max"])

    @property
    def episodes_per_iteration(self) -> int:
        """Every member's episodes are exploration: P x E episodes of T steps per generation."""
        return self.es.population * self.es.episodes_per_member
