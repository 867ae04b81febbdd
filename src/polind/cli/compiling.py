"""Compiling: ``polind precompile``, numba's cache filled once after an install."""

from __future__ import annotations

import os

import click

from polind.cli.common import cli, progress


def _cpus() -> int:
    """The processors this process may run on (its affinity where the system says)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _names(values) -> list:
    """The names of a repeatable, comma-separated option."""
    return [name.strip() for value in values for name in value.split(",") if name.strip()]


@cli.command()
@click.option("--models", "models", multiple=True, metavar="TYPES",
              help="Compile only these built-in model types, comma-separated or repeated "
                   "(e.g. --models lugre,gms). Default: every one.")
@click.option("--drivers", "drivers", multiple=True, metavar="NAMES",
              help="Run only these drivers, comma-separated or repeated: simulate-x, "
                   "simulate-v, path, Stepper, Body, BodyBatch, simulate_system, "
                   "simulate_structure, contact_period. Default: every one.")
@click.option("--jobs", "-j", "jobs", type=click.IntRange(min=1), default=None, metavar="N",
              help="Compile in N processes side by side. Default: the number of CPUs.")
@click.option("--quiet", "-q", is_flag=True, help="Print nothing (errors still go to standard "
                                                    "error).")
def precompile(models, drivers, jobs, quiet):
    """Compile every built-in model for every driver into numba's on-disk cache, once.

    Run it once after installing polind (and after upgrading it or numba):
    every later process loads the kernels from the cache instead of
    compiling them, so the first `polind simulate`, fit or demo of a model
    starts as fast as the next. Each built-in model (Pol-Ind statistical,
    at its fixed load and elastic-plastic) runs on a tiny input through
    simulate (positions and velocities), the plain path of the element fits,
    Stepper, Body, BodyBatch, simulate_system, simulate_structure and
    contact_period, each as it is and behind a series spring, at its own
    load and at a varying one. The cache is numba's (NUMBA_CACHE_DIR when
    set, else beside polind's sources or numba's user-wide folder). Once
    something needs compiling the models are shared out among --jobs
    processes; a cache that already holds everything is only loaded, in
    one process. Prints each model's kernel signatures compiled and loaded,
    its seconds, and the total time.
    """
    import time

    from polind.bench import precompile as compiler

    types = compiler.model_types(_names(models))
    chosen = compiler.driver_names(_names(drivers))
    location = compiler.cache_location()
    jobs = _cpus() if jobs is None else jobs
    work = compiler.tasks(types, chosen)
    processes = min(jobs, len(compiler.families(work)))
    if not quiet:
        where = f"in up to {processes} processes" if processes > 1 else "in one process"
        click.echo(f"polind precompile: {len(work)} model and driver pairs, {where}, into "
                   f"{location}")
    started = time.perf_counter()
    with progress(total=len(work), description="precompile", unit=" tasks") as bar:
        def shown(row):
            bar.set_postfix_str(f"{row.variant}: {row.driver}", refresh=False)
            bar.update()

        rows = compiler.run_precompile(types, chosen, jobs=jobs, progress=shown)
    seconds = time.perf_counter() - started
    if not quiet:
        click.echo(compiler.format_rows(rows))
        click.echo(f"compiled {sum(row.compiled for row in rows)} kernel signatures and loaded "
                   f"{sum(row.loaded for row in rows)} from the cache in {seconds:.1f} s")
