"""DDPG + HER (Andrychowicz et al. 2017) as an ``learners.base.Algorithm``: one iteration explores
``num_envs`` episodes in parallel, stores them whole, and takes its gradient steps on relabelled
transitions (one per ``update_every`` collected transitions as mrl, or ``n_batches`` as a Baselines
cycle), the target networks moving every ``target_every`` steps or once after them; ``eval_every``
iterations are scanned per compiled chunk. ``HerConfig`` holds the settings of either protocol.

The actor is a ``networks.Policy`` (ReLU, tanh output) whose state also holds the observation and
goal normaliser, so evaluation, rollouts and checkpoints read it as they read SPLID's policy."""

from __future__ import annotations

import contextlib

import jax
import jax.numpy as jnp
import optax
from flax import struct

from envs.base import GoalEnv, step_batch
from splid_jax.common.errors import check
from splid_jax.common.networks import CLIP_NORMALISED, MLP, Policy, PolicyState, running_statistics
from splid_jax.config import TrainConfig
from splid_jax.learners.base import Chunked
from splid_jax.learners.her.config import HerConfig
from splid_jax.learners.her.episode_buffer import (
    EpisodeBuffer,
    Transitions,
    buffer_init,
    buffer_insert,
    sample_transitions,
)


def td_target(reward: jax.Array, next_q: jax.Array, gamma: float, low: float, high: float) -> jax.Array:
    """r + gamma Q'(s', pi'(s')), clipped to the returns the sparse reward allows. Time limits are not
    terminal, so every transition bootstraps (as Baselines)."""
    return jnp.clip(reward + gamma * next_q, low, high)


def _pick(which: jax.Array, new, old):
    """``new`` where ``which`` holds, else ``old`` (pytrees of one structure)."""
    return jax.tree_util.tree_map(lambda a, b: jnp.where(which, a, b), new, old)


@struct.dataclass
class HerState:
    policy: PolicyState  # the online actor and the shared observation/goal normaliser (acts and evaluates)
    critic: dict
    target_actor: dict
    target_critic: dict
    actor_opt: optax.OptState
    critic_opt: optax.OptState
    buffer: EpisodeBuffer
    key: jax.Array
    iteration: jax.Array  # [] int32, completed iterations (cycles)


class HER(Chunked):
    """DDPG + HER; static parts only, all state flows through arguments."""

    name = "her"

    def __init__(self, env: GoalEnv, cfg: TrainConfig, her: HerConfig | None = None):
        her = cfg.learner_config() if her is None else her
        T = env.episode_length
        check(
            her.buffer_transitions >= T,
            "her.buffer_transitions",
            her.buffer_transitions,
            f"at least one episode ({T} transitions)",
        )
        self.env, self.cfg, self.her = env, cfg, her
        self.capacity = her.buffer_transitions // T
        self.n_updates = her.updates_per_iteration(cfg.num_envs * T)
        if her.update_every:
            per = f"at most the {cfg.num_envs * T} transitions an iteration collects (num_envs={cfg.num_envs} x {T})"
            check(self.n_updates >= 1, "her.update_every", her.update_every, per)
        nets = dict(hidden=her.hidden, activation="relu", layer_norm=her.layer_norm)
        if her.compute_dtype != "float32":
            nets["dtype"] = her.compute_dtype
        self.policy = Policy(
            net=MLP(**nets, action_size=env.action_size, tanh_output=True),
            in_size=env.obs_size + env.goal_size,
            normalise=True,
        )
        self.critic = MLP(**nets, action_size=1)
        self.actor_opt = optax.adam(her.actor_lr)
        self.critic_opt = optax.adam(her.critic_lr)
        # The returns the task's sparse reward allows: Baselines' [-1/(1-gamma), 0] under the Fetch
        # convention (-1 / 0), [0, 1/(1-gamma)] under the point task's (0 / 1).
        g = jnp.zeros(env.goal_size)
        rewards = (float(env.reward_of(g, g)), float(env.reward_of(g, g + 1e3)), 0.0)
        self.target_range = (min(rewards) / (1 - her.gamma), max(rewards) / (1 - her.gamma))

    def hyper(self, cfg: TrainConfig | None = None) -> dict:
        return {}  # nothing traced: a sweep's members differ only by seed

    def init(self, key: jax.Array) -> HerState:
        env = self.env
        k_actor, k_critic, k_run = jax.random.split(key, 3)
        pstate = self.policy.init(k_actor)
        critic = self.critic.init(k_critic, jnp.zeros((self.policy.in_size + env.action_size,)))
        return HerState(
            policy=pstate,
            critic=critic,
            target_actor=jax.tree_util.tree_map(jnp.copy, pstate.params),
            target_critic=jax.tree_util.tree_map(jnp.copy, critic),
            actor_opt=self.actor_opt.init(pstate.params),
            critic_opt=self.critic_opt.init(critic),
            buffer=buffer_init(self.capacity, env.episode_length, env.obs_size, env.goal_size, env.action_size),
            key=k_run,
            iteration=jnp.int32(0),
        )

    def _clip(self, x: jax.Array) -> jax.Array:
        return jnp.clip(x, -self.her.clip_obs, self.her.clip_obs)

    def _inputs(self, normaliser, obs: jax.Array, goal: jax.Array) -> jax.Array:
        """Baselines' preprocessing. ``evaluate`` goes through ``Policy.mean``, which skips the clip at
        clip_obs; that changes nothing while mean + 5 std < clip_obs, since the normalised input is
        clipped at 5 either way."""
        x = jnp.concatenate([self._clip(obs), self._clip(goal)], axis=-1)
        return running_statistics.normalize(x, normaliser, max_abs_value=CLIP_NORMALISED)

    def explore(
        self, pstate: PolicyState, key: jax.Array, random_p: jax.Array | float | None = None
    ) -> tuple[EpisodeBuffer, jax.Array, jax.Array]:
        """``num_envs`` episodes: the actor plus N(0, noise_eps^2), clipped, replaced by a uniform action
        with probability ``random_p`` (default random_eps). Returns the episodes (batch-major), their
        validity (no NaN) and whether each succeeded at any step."""
        env, her, n = self.env, self.her, self.cfg.num_envs
        random_p = her.random_eps if random_p is None else random_p
        k_reset, k_steps = jax.random.split(key)
        start = jax.vmap(env.reset)(jax.random.split(k_reset, n))

        def one_step(state, k):
            k_noise, k_coin, k_uniform = jax.random.split(k, 3)
            mean = self.policy.net.apply(pstate.params, self._inputs(pstate.normaliser, state.obs, state.desired_goal))
            action = jnp.clip(mean + her.noise_eps * jax.random.normal(k_noise, mean.shape), -1.0, 1.0)
            uniform = jax.random.uniform(k_uniform, mean.shape, minval=-1.0, maxval=1.0)
            action = jnp.where(jax.random.bernoulli(k_coin, random_p, (n, 1)), uniform, action)
            nxt = step_batch(env, state, action)
            return nxt, (nxt.obs, nxt.achieved_goal, action, nxt.success)

        final, (obs, achieved, actions, success) = jax.lax.scan(
            one_step, start, jax.random.split(k_steps, env.episode_length)
        )
        episodes = EpisodeBuffer(
            obs=jnp.swapaxes(jnp.concatenate([start.obs[None], obs]), 0, 1),
            achieved=jnp.swapaxes(jnp.concatenate([start.achieved_goal[None], achieved]), 0, 1),
            goal=start.desired_goal,
            actions=jnp.swapaxes(actions, 0, 1),
            ptr=jnp.int32(0),
            size=jnp.int32(n),
        )
        valid = ~final.invalid  # the flag stays set once a NaN was seen
        return episodes, valid, jnp.any(success, axis=0) & valid

    def update_normaliser(self, pstate: PolicyState, episodes: EpisodeBuffer, valid: jax.Array, key) -> PolicyState:
        """As Baselines: statistics of (obs, goal) over num_envs * T relabelled transitions of the new
        episodes; episodes with a NaN carry no weight."""
        n = episodes.obs.shape[0] * self.env.episode_length
        tr = sample_transitions(episodes, key, n, self.her.future_p, self.env.reward_of)  # the future strategy
        x = jnp.concatenate([self._clip(tr.obs), self._clip(tr.goal)], axis=-1)
        w = valid[tr.episode].astype(jnp.float32)
        x = jnp.where(w[:, None] > 0, x, 0.0)
        stats = running_statistics.update(pstate.normaliser, x, weights=w, std_min_value=self.her.norm_eps)
        return pstate.replace(normaliser=stats)

    def _q(self, params, x: jax.Array, a: jax.Array) -> jax.Array:
        return self.critic.apply(params, jnp.concatenate([x, a], axis=-1))[..., 0]

    def td_targets(self, hs: HerState, tr: Transitions) -> jax.Array:
        """The clipped TD targets of ``tr`` (any leading axes). The target networks and the normaliser stay
        fixed over a cycle's updates (Baselines moves the targets after them), so every batch's targets come
        from one pass before the updates rather than two small networks' passes in each."""
        x_next = self._inputs(hs.policy.normaliser, tr.next_obs, tr.goal)
        next_q = self._q(hs.target_critic, x_next, self.policy.net.apply(hs.target_actor, x_next))
        return td_target(tr.reward, next_q, self.her.gamma, *self.target_range)

    def losses(self, actor, critic, pstate: PolicyState, tr: Transitions, target: jax.Array):
        """Critic: squared error to the clipped TD ``target``; actor: -Q(s, pi(s)) + action_l2 * pi^2."""
        x = self._inputs(pstate.normaliser, tr.obs, tr.goal)

        def critic_loss(params):
            q_data = self._q(params, x, tr.action)
            return jnp.mean((target - q_data) ** 2), q_data

        def actor_loss(params):
            pi = self.policy.net.apply(params, x)
            return -jnp.mean(self._q(critic, x, pi)) + self.her.action_l2 * jnp.mean(pi**2)

        (c_loss, q_data), c_grad = jax.value_and_grad(critic_loss, has_aux=True)(critic)
        a_loss, a_grad = jax.value_and_grad(actor_loss)(actor)
        return c_loss, a_loss, jnp.mean(q_data), c_grad, a_grad

    def _moved_targets(self, hs: HerState) -> HerState:
        step = 1.0 - self.her.polyak
        return hs.replace(
            target_actor=optax.incremental_update(hs.policy.params, hs.target_actor, step),
            target_critic=optax.incremental_update(hs.critic, hs.target_critic, step),
        )

    def warm(self, buffer: EpisodeBuffer) -> jax.Array:
        """Whether the buffer holds enough to learn from: an episode, and ``warm_up`` transitions."""
        return (buffer.size > 0) & (buffer.size * self.env.episode_length >= self.her.warm_up)

    def train_step(self, hs: HerState, batch: tuple[Transitions, jax.Array]) -> tuple[HerState, dict]:
        """One gradient step of critic and actor, both from the same batch at the same parameters (as
        Baselines computes them in one pass)."""
        tr, target = batch
        c_loss, a_loss, q_mean, c_grad, a_grad = self.losses(hs.policy.params, hs.critic, hs.policy, tr, target)
        c_upd, critic_opt = self.critic_opt.update(c_grad, hs.critic_opt, hs.critic)
        a_upd, actor_opt = self.actor_opt.update(a_grad, hs.actor_opt, hs.policy.params)
        hs = hs.replace(
            critic=optax.apply_updates(hs.critic, c_upd),
            critic_opt=critic_opt,
            policy=hs.policy.replace(params=optax.apply_updates(hs.policy.params, a_upd)),
            actor_opt=actor_opt,
        )
        return hs, {"critic_loss": c_loss, "actor_loss": a_loss, "q_mean": q_mean}

    @staticmethod
    def _learnt(hs: HerState) -> tuple:
        return hs.critic, hs.critic_opt, hs.policy.params, hs.actor_opt

    def draw(self, hs: HerState, key: jax.Array, n: int) -> Transitions:
        """``n`` batches, each from its own key as one at a time would draw it."""
        her, T = self.her, self.env.episode_length
        actual_on = hs.buffer.size * T >= her.actual_warm_up

        def one(k):
            return sample_transitions(
                hs.buffer, k, her.batch_size, her.future_p, self.env.reward_of, her.actual_p, actual_on
            )

        return jax.vmap(one)(jax.random.split(key, n))

    def updates(self, hs: HerState, key: jax.Array) -> tuple[HerState, dict]:
        """An iteration's ``n_updates`` gradient steps, kept once the buffer is ``warm`` (before that the
        networks and optimisers stay as they were; the losses are those of the discarded steps). The buffer
        does not change between the steps, so the warm-up is decided once for all of them (a selection per
        step costs a pass over every parameter and moment), and their batches are drawn at once. Where the
        targets stay fixed over them (``target_every`` 0, Baselines), so do their TD targets, computed in
        one pass before the steps; otherwise the targets move every ``target_every`` steps; where that
        divides the step count, each block of ``target_every`` steps takes its targets in one pass, since
        the target networks hold still over it."""
        precision = self.her.matmul_precision
        with contextlib.nullcontext() if precision == "default" else jax.default_matmul_precision(precision):
            stepped, losses = self._updates(hs, key)
        critic, critic_opt, actor, actor_opt = _pick(self.warm(hs.buffer), self._learnt(stepped), self._learnt(hs))
        stepped = stepped.replace(
            critic=critic, critic_opt=critic_opt, policy=stepped.policy.replace(params=actor), actor_opt=actor_opt
        )
        return stepped, losses

    def _updates(self, hs: HerState, key: jax.Array) -> tuple[HerState, dict]:
        her = self.her
        batches = self.draw(hs, key, self.n_updates)
        if not her.target_every:
            return jax.lax.scan(self.train_step, hs, (batches, self.td_targets(hs, batches)))

        def moved_if(hs, move):
            moved = self._moved_targets(hs)
            targets = _pick(move, (moved.target_actor, moved.target_critic), (hs.target_actor, hs.target_critic))
            return hs.replace(target_actor=targets[0], target_critic=targets[1])

        blocks, rest = divmod(self.n_updates, her.target_every)
        if not rest:  # the targets hold still over each block of target_every steps: one pass for its targets

            def block(hs, tr):
                hs, losses = jax.lax.scan(self.train_step, hs, (tr, self.td_targets(hs, tr)))
                return moved_if(hs, self.warm(hs.buffer)), losses

            split = jax.tree_util.tree_map(lambda x: x.reshape(blocks, her.target_every, *x.shape[1:]), batches)
            hs, losses = jax.lax.scan(block, hs, split)
            return hs, jax.tree_util.tree_map(lambda x: x.reshape(self.n_updates, *x.shape[2:]), losses)

        def step(hs, inputs):
            i, tr = inputs
            hs, losses = self.train_step(hs, (tr, self.td_targets(hs, tr)))
            return moved_if(hs, ((i + 1) % her.target_every == 0) & self.warm(hs.buffer)), losses

        return jax.lax.scan(step, hs, (jnp.arange(self.n_updates), batches))

    def iteration(self, hs: HerState, hyper) -> tuple[HerState, dict]:
        """Explore, store, update the normaliser, then the gradient steps (and the targets after them where
        they move once per iteration)."""
        key, k_explore, k_norm, k_train = jax.random.split(hs.key, 4)
        collected = hs.iteration * (self.cfg.num_envs * self.env.episode_length)
        random_p = jnp.where(collected < self.her.random_transitions, 1.0, self.her.random_eps)
        episodes, valid, success = self.explore(hs.policy, k_explore, random_p)
        hs = hs.replace(
            buffer=buffer_insert(hs.buffer, episodes, valid),
            policy=self.update_normaliser(hs.policy, episodes, valid, k_norm),
        )
        hs, losses = self.updates(hs, k_train)
        if not self.her.target_every:
            hs = self._moved_targets(hs)
        hs = hs.replace(key=key, iteration=hs.iteration + 1)
        metrics = {k: jnp.mean(v) for k, v in losses.items()}
        metrics["losses_finite"] = jnp.all(jnp.isfinite(losses["critic_loss"]) & jnp.isfinite(losses["actor_loss"]))
        metrics["explore_success"] = jnp.mean(success)
        return hs, metrics

    def chunk_metrics(self, hs: HerState, hyper, per_iter: dict) -> dict:
        return dict(
            critic_loss=per_iter["critic_loss"][-1],
            actor_loss=per_iter["actor_loss"][-1],
            q_mean=per_iter["q_mean"][-1],
            explore_success=jnp.mean(per_iter["explore_success"]),
            buffer_size=hs.buffer.size,
        )

    def watched(self, hs: HerState, per_iter: dict) -> tuple:
        return (hs.policy.params, hs.critic), per_iter["losses_finite"]
