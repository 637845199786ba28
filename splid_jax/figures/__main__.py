"""``python -m splid_jax.figures FIG ...``: the command line."""

from splid_jax.cli import check_environment, exit_with, quiet_interrupts, run_main

if __name__ == "__main__":
    quiet_interrupts()  # before the figure modules load JAX: a signal then ends the process with one line
    check_environment()
    from splid_jax.figures.cli import main

    exit_with(run_main(main))
