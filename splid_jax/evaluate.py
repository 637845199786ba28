"""``python -m splid_jax.evaluate RUN_DIR --reference``: a run's policy in Gymnasium-Robotics'
``Fetch*-v4`` beside our task (``splid_jax.reference``)."""

from splid_jax.cli import check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":  # a signal while JAX loads ends the process with one line, no traceback
    quiet_interrupts()
    check_environment()

from splid_jax.reference.cli import main  # noqa: E402

if __name__ == "__main__":
    exit_with(run_main(main))
