from splid_jax import rollout
from splid_jax.train import main as train_main


def test_rollout_loads_a_checkpoint_and_draws(tmp_path, capsys):
    run_dir = tmp_path / "run"
    assert train_main(["--env", "point", "--num-envs", "4", "--iterations", "2", "--eval-every", "2",
                       "--eval-episodes", "8", "--bc-steps", "5", "--hidden", "16", "--run-dir", str(run_dir),
                       "--quiet"]) == 0  # fmt: skip
    assert rollout.main([str(run_dir), "--episodes", "4"]) == 0
    out = capsys.readouterr().out
    assert "iteration 2" in out and "success" in out
    png = (run_dir / "rollout.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and len(png) > 10_000


def test_rollout_of_a_missing_run_is_a_clear_error(tmp_path, capsys):
    assert rollout.main([str(tmp_path / "nothing")]) == 2
    assert "run_dir" in capsys.readouterr().err
