"""Algorithm 2 as one pure, scanned program: ``explore -> select -> insert -> bc`` per
iteration, ``eval_every`` iterations and one evaluation per compiled chunk."""

from __future__ import annotations

import jax
import jax.numpy as jnp
import optax
from flax import struct
from jax.sharding import Mesh
from jax.sharding import PartitionSpec as P

from envs.base import GoalEnv
from splid_jax.common import ticks
from splid_jax.common.errors import check
from splid_jax.common.networks import PolicyState, make_policy
from splid_jax.common.subgoals import traced_reach
from splid_jax.config import TrainConfig
from splid_jax.learners import gcsl, registry
from splid_jax.learners.base import Chunked
from splid_jax.learners.imitation import relabel_buffer
from splid_jax.learners.imitation.bc import bc_epoch
from splid_jax.learners.imitation.candidates import Candidates
from splid_jax.learners.imitation.config import ImitationConfig
from splid_jax.learners.imitation.explore import Seen, Trajectory, draws, hold_fingers, rollout
from splid_jax.learners.splid.relabel import STRATEGIES
from splid_jax.learners.splid.select import select


@struct.dataclass
class TrainState:
    policy: PolicyState  # the acting policy (explore, SELECT, eval, checkpoints' rollouts)
    opt_state: optax.OptState
    online: dict | None  # the cloned parameters when they differ from the acting ones (policy_ema > 0)
    buffer: relabel_buffer.Buffer
    key: jax.Array
    iteration: jax.Array  # [] int32, completed iterations


@struct.dataclass
class Hyper:
    """Hyper-parameters that may differ between members of one vmapped sweep (the registry's ``sweeps``).
    The state holds an online copy of the parameters only when the sweep's own policy_ema is > 0."""

    sigma: jax.Array  # [] float32
    horizon: jax.Array  # [] int32, <= the trainer's max_horizon
    horizon_end: jax.Array  # [] int32, the horizon the annealing ends at (0: H throughout)
    sigma_end: jax.Array  # [] float32
    learning_rate: jax.Array  # [] float32
    acting_step: jax.Array  # [] float32: 1 - policy_ema, taken in double as a constant's would be
    gripper_hold: jax.Array  # [] int32, steps the fingers' noise is held (tasks that move them)
    explore_reach: jax.Array  # [] float32, exploration's subgoal reach (inf: the goal itself)
    bc_reuse: jax.Array  # [] float32, BC samples per new pair (0: the configured steps every iteration)
    held_share: jax.Array  # [] float32, the share of each BC batch drawn from the held (zero-action) pairs
    buffer_window: jax.Array  # [] int32, BC draws from the newest this many pairs (the capacity: all)
    buffer_window_grow: jax.Array  # [] int32, iterations over which the window grows to the capacity (0: fixed)


def optimiser(name: str, learning_rate) -> optax.GradientTransformation:
    """Behaviour cloning's optimiser: Adam, or RMSprop as PyTorch's (decay 0.99, eps outside the root), the
    authors' released code's."""
    if name == "rmsprop":
        return optax.rmsprop(learning_rate, decay=0.99, eps=1e-8, eps_in_sqrt=False)
    return optax.adam(learning_rate)


class Trainer(Chunked):
    """The behaviour-cloning learners as ``learners.base.Algorithm``s: SPLID, PCHID (SPLID whose
    horizon grows from 1 to H) and GCSL (every relabelled pair cloned), as the registry describes
    each (``grows_horizon``, ``clones_every_pair``). Holds what is
    static (task, network, optimiser, shapes); all state flows through arguments.

    With a ``mesh`` (one axis: the envs') each device explores and SELECTs its slice of the
    envs; the pairs come back in the one-device layout, and insertion, BC and the parameters are
    replicated, so the run computes what one device would, up to float rounding."""

    def __init__(self, env: GoalEnv, cfg: TrainConfig, mesh: Mesh | None = None):
        bc = cfg.learner_config()
        check(isinstance(bc, ImitationConfig), "algo", cfg.algo, "a behaviour-cloning learner (splid, gcsl, pchid)")
        cfg.check_env(env)
        self.env, self.cfg, self.bc, self.name = env, cfg, bc, cfg.algo
        self.learner = registry.get(cfg.algo)
        # shapes; a sweep's members mask larger h through Hyper.horizon
        self.max_horizon = bc.horizon
        self.pchid_every = max(1, bc.pchid_every)  # TrainConfig resolves 0 for pchid
        allowed = "0 for pchid, whose horizon grows over the run"
        check(not (self.learner.grows_horizon and bc.horizon_end), "horizon_end", bc.horizon_end, allowed)
        self.policy = make_policy(
            env.obs_size,
            env.goal_size,
            env.action_size,
            bc.hidden,
            bc.normalise,
            achieved_start=env.achieved_goal_start if bc.relative_goal else None,
            goal_unit=env.success_distance,
        )
        if mesh is not None:
            check(cfg.num_envs % mesh.size == 0, "num_envs", cfg.num_envs, f"a multiple of the {mesh.size} devices")
            # a model first built inside shard_map's trace would carry its manual axis into evaluation
            getattr(env, "mjx_model", None)
        self.mesh = mesh

    def hyper(self, cfg: TrainConfig | None = None) -> Hyper:
        bc = self.bc if cfg is None else cfg.learner_config()
        return Hyper(
            sigma=jnp.float32(bc.sigma),
            horizon=jnp.int32(bc.horizon),
            horizon_end=jnp.int32(bc.horizon_end),
            sigma_end=jnp.float32(bc.sigma_end),
            learning_rate=jnp.float32(bc.learning_rate),
            acting_step=jnp.float32(1.0 - bc.policy_ema),
            gripper_hold=jnp.int32(bc.gripper_hold),
            explore_reach=traced_reach(bc.explore_subgoal_reach),
            bc_reuse=jnp.float32(bc.bc_reuse),
            held_share=jnp.float32(bc.held_share),
            buffer_window=jnp.int32(bc.buffer_window or self.bc.buffer_size),
            buffer_window_grow=jnp.int32(bc.buffer_window_grow),
        )

    def init(self, key: jax.Array) -> TrainState:
        k_policy, k_run = jax.random.split(key)
        pstate = self.policy.init(k_policy)
        env, bc = self.env, self.bc
        return TrainState(
            policy=pstate,
            opt_state=optimiser(bc.optimiser, bc.learning_rate).init(pstate.params),  # the same state at any rate
            online=None if bc.policy_ema == 0 else jax.tree_util.tree_map(jnp.copy, pstate.params),
            buffer=relabel_buffer.init(bc.buffer_size, env.obs_size, env.goal_size, env.action_size),
            key=k_run,
            iteration=jnp.int32(0),
        )

    def iteration(self, ts: TrainState, hyper: Hyper) -> tuple[TrainState, dict]:
        """One iteration; with a mesh, every device runs this same program on the whole state and
        only exploration and SELECT are split (``explore_and_select``), so the run computes bit for
        bit what one device computes."""
        if self.mesh is None:
            return self._iteration(ts, hyper)
        whole = P()
        return jax.shard_map(
            self._iteration, mesh=self.mesh, in_specs=(whole, whole), out_specs=(whole, whole), check_vma=False
        )(ts, hyper)

    def _iteration(self, ts: TrainState, hyper: Hyper) -> tuple[TrainState, dict]:
        env, cfg, bc, policy = self.env, self.cfg, self.bc, self.policy
        key, k_explore, k_bc, k_relabel = jax.random.split(ts.key, 4)
        reset_keys, noise = draws(env, k_explore, cfg.num_envs)
        if env.moves_fingers:
            noise = hold_fingers(noise, hyper.gripper_hold)
        horizon = self.horizon_at(ts.iteration, hyper)
        sigma = self.sigma_at(ts.iteration, hyper)
        seen, cands = self.explore_and_select(
            ts.policy, reset_keys, noise, sigma, horizon, hyper.explore_reach, ts.iteration
        )
        if self.learner.clones_every_pair:
            cands = gcsl.relabel(env, seen, bc.gcsl_relabel, k_relabel)
        buf = relabel_buffer.insert(ts.buffer, cands.obs, cands.goal, cands.action, cands.accept)
        pstate = policy.update_normaliser(ts.policy, seen.obs, seen.achieved[:-1], ~seen.invalid[:-1])
        stored = jnp.sum(cands.accept, dtype=jnp.int32)
        steps = self.bc_steps_for(stored, hyper)
        now = hyper.replace(buffer_window=self.window_at(ts.iteration, hyper))
        pstate, opt_state, online, loss = self.clone(pstate, ts.opt_state, ts.online, buf, k_bc, now, steps)
        metrics = {
            "select_pairs": jnp.sum(cands.valid, dtype=jnp.int32),
            "select_held": jnp.sum(cands.valid & cands.held, dtype=jnp.int32),
            "select_held_accepted": jnp.sum(cands.accept & cands.held, dtype=jnp.int32),
            "select_accepted": stored,
            "select_steps": cands.replay_steps,
            "bc_steps": steps,
            "bc_loss": loss,
            "explore_success": jnp.mean(jnp.any(seen.success, axis=0)),
        }
        new = TrainState(
            policy=pstate, opt_state=opt_state, online=online, buffer=buf, key=key, iteration=ts.iteration + 1
        )
        return new, metrics

    def explore_and_select(
        self, pstate, reset_keys, noise, sigma, horizon, reach, iteration=None
    ) -> tuple[Seen, Candidates | None]:
        """Explore the envs and, but for GCSL, SELECT among their relabelled pairs: all of them, or,
        inside the mesh's ``shard_map``, this device's slice, gathered back in the one-device layout.
        ``iteration`` (completed iterations) goes to the progress ticks."""
        if self.mesh is None:
            return self._explore_and_select(pstate, reset_keys, noise, sigma, horizon, reach, iteration)
        (axis,) = self.mesh.axis_names
        n = self.cfg.num_envs // self.mesh.size
        first = jax.lax.axis_index(axis) * n
        seen, cands = self._explore_and_select(
            pstate,
            jax.lax.dynamic_slice_in_dim(reset_keys, first, n, axis=0),
            jax.lax.dynamic_slice_in_dim(noise, first, n, axis=1),
            sigma,
            horizon,
            reach,
        )
        gather = lambda x: jax.lax.all_gather(x, axis, axis=1, tiled=True)  # noqa: E731  [T, n] -> [T, N]
        seen = jax.tree.map(gather, seen)
        if cands is None:
            return seen, None
        # [H*T*n] in layout [H, T, n] -> [H*T, N] -> the one-device layout [H, T, N]
        whole = [gather(x.reshape((-1, n) + x.shape[1:])).reshape((-1,) + x.shape[1:]) for x in cands[:-1]]
        return seen, Candidates(*whole, jax.lax.psum(cands.replay_steps, axis))

    def _explore_and_select(
        self, pstate, reset_keys, noise, sigma, horizon, reach, iteration=None
    ) -> tuple[Seen, Candidates | None]:
        traj = rollout(self.env, self.policy, pstate, reset_keys, noise, sigma, reach)
        if iteration is not None:
            ticks.tick(ticks.EXPLORED, lambda: iteration, after=traj.actions[-1, 0, 0])
        if self.learner.clones_every_pair:
            return traj.seen(), None
        return traj.seen(), self.select(pstate, traj, horizon)

    def bc_steps_for(self, stored: jax.Array, hyper: Hyper) -> jax.Array:
        """This iteration's BC steps: with ``bc_reuse``, enough minibatches to draw each newly stored pair
        that many times on average, in [1, bc_steps]; otherwise bc_steps."""
        bc = self.bc
        wanted = jnp.ceil(hyper.bc_reuse * stored.astype(jnp.float32) / bc.batch_size).astype(jnp.int32)
        return jnp.where(hyper.bc_reuse > 0, jnp.clip(wanted, 1, bc.bc_steps), bc.bc_steps)

    def window_at(self, iteration: jax.Array, hyper: Hyper) -> jax.Array:
        """BC's window this iteration: buffer_window, growing linearly to the buffer's capacity over the first
        buffer_window_grow iterations."""
        grow = hyper.buffer_window_grow
        fraction = jnp.minimum(1.0, iteration.astype(jnp.float32) / jnp.maximum(grow, 1).astype(jnp.float32))
        grown = hyper.buffer_window + jnp.round((self.bc.buffer_size - hyper.buffer_window) * fraction)
        return jnp.where(grow > 0, grown.astype(jnp.int32), hyper.buffer_window)

    def clone(self, pstate, opt_state, online, buf: relabel_buffer.Buffer, key, hyper: Hyper, steps=None):
        """Behaviour cloning on the buffer, at ``hyper``'s rate and acting average, ``steps`` of the
        configured bc_steps (all when None): the one place the settings become BC's arguments. Returns
        (pstate, opt_state, online, mean loss)."""
        bc = self.bc
        return bc_epoch(
            self.policy,
            optimiser(bc.optimiser, hyper.learning_rate),
            pstate,
            opt_state,
            buf,
            key,
            bc.bc_steps,
            bc.batch_size,
            online,
            hyper.acting_step,
            steps,
            hyper.buffer_window,
            hyper.held_share if STRATEGIES[bc.relabel].stands_still else None,  # held pairs found by their zero action
        )

    def select(self, pstate, traj: Trajectory, horizon: jax.Array) -> Candidates:
        """SELECT over one exploration's relabelled candidates, as this run's settings ask for."""
        bc = self.bc
        return select(
            self.env,
            self.policy,
            pstate,
            traj,
            self.max_horizon,
            horizon,
            bc.select,
            bc.select_lanes,
            bc.relabel,
        )

    def sigma_at(self, iteration: jax.Array, hyper: Hyper) -> jax.Array:
        """This iteration's exploration noise: sigma, falling linearly to sigma_end x sigma over the
        first sigma_anneal iterations."""
        fraction = optax.linear_schedule(1.0, hyper.sigma_end, max(1, self.bc.sigma_anneal - 1))
        return hyper.sigma * fraction(iteration)

    def horizon_at(self, iteration: jax.Array, hyper: Hyper) -> jax.Array:
        """The learning horizon of this iteration: H (falling to horizon_end with the noise's annealing), or
        PCHID's curriculum 1, 2, ..., H."""
        if not self.learner.grows_horizon:
            left = optax.linear_schedule(1.0, 0.0, max(1, self.bc.sigma_anneal - 1))(iteration)
            end = hyper.horizon_end
            falling = jnp.round(end + (hyper.horizon - end) * left).astype(jnp.int32)
            return jnp.where(end > 0, falling, hyper.horizon)
        return jnp.minimum(hyper.horizon, 1 + iteration // self.pchid_every).astype(jnp.int32)

    def chunk_metrics(self, ts: TrainState, hyper: Hyper, per_iter: dict) -> dict:
        return dict(
            select_pairs=jnp.sum(per_iter["select_pairs"]),
            select_accepted=jnp.sum(per_iter["select_accepted"]),
            select_held=jnp.sum(per_iter["select_held"]),
            select_held_accepted=jnp.sum(per_iter["select_held_accepted"]),
            horizon=self.horizon_at(ts.iteration - 1, hyper),
            sigma=self.sigma_at(ts.iteration - 1, hyper),
            select_steps=per_iter["select_steps"],  # [eval_every]: summed on the host, where ints do not overflow
            bc_loss=per_iter["bc_loss"][-1],
            bc_steps=jnp.mean(per_iter["bc_steps"].astype(jnp.float32)),
            explore_success=jnp.mean(per_iter["explore_success"]),
            buffer_size=ts.buffer.size,
        )

    def watched(self, ts: TrainState, per_iter: dict) -> tuple:
        return (ts.policy.params, ts.online), jnp.isfinite(per_iter["bc_loss"])
