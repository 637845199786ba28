from splid_jax import rollout
from splid_jax.train import main as train_main


def test_rollout_loads_a_checkpoint_and_draws(tmp_path, capsys):
    run_dir = tmp_path / "run"
    assert train_main(["--env", "point", "--num-envs", "4", "--iterations", "2", "--eval-every", "2",
                       "--eval-episodes", "8", "--bc-steps", "5", "--hidden", "16", "--run-dir", str(run_dir),
                       "--quiet"]) == 0  # fmt: skip
    assert rollout.main([str(run_dir), "--episodes", "4"]) == 0
    out, err = capsys.readouterr()
    assert "iteration 2" in out and "success" in out
    assert "another version of the task" not in err
    png = (run_dir / "rollout.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_rollout_of_a_missing_run_is_a_clear_error(tmp_path, capsys):
    assert rollout.main([str(tmp_path / "nothing")]) == 2
    assert "run_dir" in capsys.readouterr().err


def test_rollout_says_when_the_task_changed_since_training(tmp_path, capsys):
    import envs
    from splid_jax.config import TrainConfig
    from splid_jax.train import run

    cfg = TrainConfig(env="point", num_envs=4, eval_episodes=4, bc_steps=2, batch_size=16, hidden=(8,),
                      eval_every=2, iterations=2, run_dir=str(tmp_path / "run"))  # fmt: skip
    run(cfg, env=envs.make("point", door_half_width=0.5), quiet=True)  # as if trained before a default changed
    assert rollout.main([cfg.run_dir, "--episodes", "4"]) == 0
    err = capsys.readouterr().err
    assert "another version of the task" in err and "door_half_width=0.5 then, 0.75 now" in err
