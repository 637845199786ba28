"""A learner's chunk as two programs: the same state and metrics as one program, compiled at once."""

import functools
import threading

import jax
import jax.numpy as jnp
import numpy as np

import envs
from splid_jax.config import TrainConfig
from splid_jax.learners.her.config import HerConfig
from splid_jax.learners.her.learner import HER
from splid_jax.learners.splid.trainer import Trainer
from splid_jax.runtime import programs
from splid_jax.runtime.signals import Signals

# small networks and buffers (SPLID's default buffer of 200,000 pairs and three layers of 64 compile seconds longer):
# the split is the same at any size
CFG = dict(env="point", num_envs=8, iterations=4, eval_every=2, bc_steps=4, batch_size=32, eval_episodes=16,
           hidden=(16, 16), buffer_size=1000)  # fmt: skip
HER_CFG = dict(batch_size=32, update_every=0, n_batches=2, hidden=(16, 16), buffer_transitions=2000)


def strong(tree):  # as the host loop places state and settings
    return jax.tree.map(lambda x: jnp.array(x, dtype=jnp.result_type(x)), tree)


def abstract(tree):
    return jax.tree.map(lambda x: jax.ShapeDtypeStruct(x.shape, x.dtype, sharding=x.sharding), tree)


def two_chunks(learner, chunk):
    state, hyper, out = strong(learner.init(jax.random.PRNGKey(3))), strong(learner.hyper()), []
    for _ in range(2):
        state, metrics = chunk(state, hyper)
        out.append(jax.device_get(metrics))
    return jax.device_get(state), out


def test_training_and_report_as_two_programs_give_the_one_programs_chunk():
    for learner in (
        Trainer(envs.make("point"), TrainConfig(**CFG)),
        HER(envs.make("point"), TrainConfig(**{**CFG, "num_envs": 4}, algo="her"), HerConfig(**HER_CFG)),
    ):
        fns = programs.parts(learner, stacked=False)
        assert len(fns) == 2
        state, hyper = strong(learner.init(jax.random.PRNGKey(3))), strong(learner.hyper())
        split = programs.compile_all(programs.trace(fns, abstract(state), abstract(hyper)), Signals())
        one, two = two_chunks(learner, jax.jit(learner.chunk)), two_chunks(learner, split)
        # to float rounding: under the suite's XLA:CPU flags the two modules fuse differently (without
        # them, and for the metrics here, bit for bit)
        close = functools.partial(np.testing.assert_allclose, rtol=1e-5, atol=1e-6, err_msg=learner.name)
        jax.tree.map(close, one, two)


def test_the_two_programs_compile_at_once(monkeypatch):
    both = threading.Barrier(2, timeout=30)  # broken, and the test failed, if one compile waits for the other
    compile_ = jax.stages.Lowered.compile

    def met(self, *a, **kw):
        both.wait()
        return compile_(self, *a, **kw)

    monkeypatch.setattr(jax.stages.Lowered, "compile", met)
    learner = Trainer(envs.make("point"), TrainConfig(**CFG))
    state, hyper = strong(learner.init(jax.random.PRNGKey(0))), strong(learner.hyper())
    chunk = programs.compile_all(programs.trace(programs.parts(learner, False), abstract(state), abstract(hyper)),
                                 Signals())  # fmt: skip
    assert len(chunk.programs) == 2 and chunk.bytes_needed() > 0


def test_an_algorithm_with_a_chunk_alone_is_one_program():
    class Plain:
        def chunk(self, state, hyper):
            return state + hyper, {"finite": True}

    fns = programs.parts(Plain(), stacked=True)
    like = jax.ShapeDtypeStruct((3,), np.float32)
    chunk = programs.compile_all(programs.trace(fns, like, like), Signals())
    assert len(chunk.programs) == 1
    np.testing.assert_array_equal(chunk(np.ones(3, np.float32), np.ones(3, np.float32))[0], 2 * np.ones(3))
