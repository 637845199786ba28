"""Every learner through the command line and the one host loop, on the point task at tiny sizes: the
one metrics schema, and a run stopped at a checkpoint and resumed equals one run straight through, bit
for bit. Each algorithm's chunk compiles once here; its later runs read it from the compile cache."""

import json
import os
import shutil

import jax
import numpy as np
import pytest

import envs
from splid_jax.config import TrainConfig
from splid_jax.learners import registry
from splid_jax.runtime import checkpoint, run_files
from splid_jax.train import main

COMMON = ["--env", "point", "--eval-every", "2", "--eval-episodes", "16", "--quiet"]
BC = ["--num-envs", "8", "--hidden", "16,16", "--bc-steps", "4", "--batch-size", "32", "--buffer-size", "1000"]
ARGS = {
    "splid": BC,
    "gcsl": BC,
    "pchid": [*BC, "--pchid-every", "1"],  # a fixed schedule: the default follows --iterations
    "her": [
        "--num-envs",
        "4",
        "--her-options",
        "batch_size=32,update_every=0,n_batches=2,hidden=16,16,buffer_transitions=2000",
    ],
    "es": ["--hidden", "16,16", "--es-options", "population=8"],
}
SCHEMA = ("iteration", "episodes", "env_steps", "select_steps", "eval_success", "eval_success_final", "eval_return",
          "wall_s")  # fmt: skip
VOLATILE = {"wall_s", "steps_per_s"}


def train(algo, run_dir, *extra):
    return main(["--algo", algo, *COMMON, *ARGS[algo], "--run-dir", str(run_dir), *extra])


def stable(run_dir):
    records = run_files.read_metrics(f"{run_dir}/metrics.jsonl")
    return [{k: v for k, v in r.items() if k not in VOLATILE} for r in records]


def final_state(run_dir):
    with open(os.path.join(run_dir, "config.json")) as fh:
        cfg = TrainConfig.from_json(json.load(fh))
    algo = registry.make_algorithm(cfg, envs.make(cfg.env))
    step, state, _ = checkpoint.restore(str(run_dir), jax.eval_shape(algo.init, jax.random.PRNGKey(0)))
    return step, jax.tree_util.tree_leaves(state)


@pytest.mark.parametrize("algo", ["splid", "gcsl", "pchid", "her", "es"])
def test_each_algo_writes_the_schema_and_resumes_bit_for_bit(tmp_path, algo):
    straight, killed = tmp_path / "straight", tmp_path / "killed"
    assert train(algo, straight, "--iterations", "4") == 0
    # As if killed after the checkpoint at iteration 2: the newer one is gone, its metrics line is not yet
    shutil.copytree(straight, killed)
    shutil.rmtree(killed / "checkpoints" / "4")
    assert main(["--resume", str(killed), "--iterations", "4", "--quiet"]) == 0

    records = stable(straight)
    assert [r["iteration"] for r in records] == [2, 4]
    assert all(set(SCHEMA) <= set(r) for r in run_files.read_metrics(f"{straight}/metrics.jsonl"))
    assert all(0 <= r["eval_success"] <= 1 and 0 <= r["eval_success_final"] <= r["eval_success"] for r in records)
    per_iteration = 4 if algo == "her" else 8  # ES: its population of 8, each member's episode
    assert records[-1]["episodes"] == 4 * per_iteration
    assert records[-1]["env_steps"] == 4 * per_iteration * envs.make("point").episode_length
    assert json.load(open(straight / "config.json"))["algo"] == algo

    assert stable(killed) == records
    (step_a, a), (step_b, b) = final_state(straight), final_state(killed)
    assert step_a == step_b == 4
    for x, y in zip(a, b, strict=True):
        np.testing.assert_array_equal(np.asarray(x), np.asarray(y))


@pytest.mark.parametrize(
    "args,field",
    [
        (["--algo", "her", "--her-options", "batch_size=0"], "her.batch_size"),
        (["--algo", "her", "--her-options", "bogus=1"], "--her-options bogus="),  # no flag of that name: as typed
        (["--algo", "her", "--her-options", "gamma=big"], "her.gamma"),
        (["--algo", "her", "--her-options", "hidden=16,x"], "her.hidden"),
        (["--algo", "her", "--her-options", "n_batches"], "her_options"),
        (["--algo", "es", "--es-options", "population=7"], "es.population"),  # antithetic pairs
        (["--algo", "es", "--es-options", "antithetic=maybe"], "es.antithetic"),
        (["--algo", "splid", "--her-options", "batch_size=32"], "her_options"),  # another algo's options
        (["--algo", "her", "--es-options", "population=8"], "es_options"),
        (["--algo", "es", "--num-envs", "8"], "num_envs"),  # the population sets it
        (["--algo", "her", "--her-batch-size", "0"], "her.batch_size"),
        (["--algo", "splid", "--her-batch-size", "32"], "her.batch_size"),  # as typed
        (["--algo", "her", "--hidden", "16"], "hidden"),  # HER's networks are her_options'
        (["--algo", "es", "--sigma", "0.5"], "sigma"),
    ],
)
def test_bad_algo_options_are_one_line_naming_the_field(tmp_path, capsys, args, field):
    assert main([*args, "--run-dir", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip()
    typed = field if field.endswith("=") else f"--{field.replace('.', '-').replace('_', '-')} "
    assert len(err.splitlines()) == 1 and f"invalid {typed}" in err
    assert not (tmp_path / "run").exists()


def test_options_reach_the_config_with_their_types():
    her = TrainConfig(algo="her", her_options="hidden=16,16,batch_size=32,polyak=0.9").learner_config()
    assert (her.hidden, her.batch_size, her.polyak) == ((16, 16), 32, 0.9)
    es = TrainConfig(algo="es", es_options="population=8,episodes_per_member=2,antithetic=false")
    assert es.learner_config().antithetic is False and es.num_envs == 16  # episodes per generation
    assert TrainConfig(algo="her").learner_config().batch_size == 2000  # mrl's


def test_her_takes_its_own_defaults_on_fetch_tasks_only():
    push = TrainConfig(env="push", algo="her")
    assert (push.num_envs, push.eval_every, push.iterations * push.num_envs) == (8, 25, 20_000)
    assert TrainConfig(env="push").num_envs == 125 and TrainConfig(env="point", algo="her").num_envs == 32
    assert TrainConfig(env="push", algo="her", num_envs=32).num_envs == 32  # given values win
    assert push.env_overrides() == {} and TrainConfig(env="push").env_options == ""
    given = TrainConfig(env="push", algo="her", env_options="finger=box,solver_loops=loops")
    assert given.env_overrides() == {"finger": "box", "solver_loops": "loops"}  # option by option, given ones win
    carry = TrainConfig(env="pick_and_place", algo="her").env_overrides()  # mrl's: the standard starts
    assert carry == {"grasped_starts": 0}


def test_help_lists_each_learners_fields_and_defaults(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    text = " ".join(capsys.readouterr().out.split())
    assert "--her-batch-size BATCH_SIZE transitions per gradient step (default: 2000)" in text
    assert "--her-replay-k REPLAY_K" in text and "--es-population POPULATION" in text
    assert "her on reach, push, slide, pick_and_place: 8" in text
    assert "her on push, pick_and_place: 2500" in text and "her on slide: 6250" in text
