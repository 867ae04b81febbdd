"""Exports of a model for other tools: ``polind fmu``."""

from __future__ import annotations

import os

import click

from polind.cli.common import (check_output_path, cli, load_model, model_argument,
                               output_option, refuse_overwriting_inputs)
from polind.errors import InputError


@cli.command()
@model_argument
@output_option
@click.option("--input", "input_name", type=click.Choice(["x", "force"]), default="x",
              show_default=True,
              help="x: input the position x [m], output the friction F [N] (polind.Stepper). "
                   "force: input the applied force [N], outputs x, v, F (polind.Body).")
@click.option("--mass", type=float, default=None, metavar="M",
              help="The body's mass [kg] (--input force; default 1).")
@click.option("--time-step", "time_step", type=float, default=None, metavar="H",
              help="The body's time step [s] (--input force; default 1e-3): a communication "
                   "step must be a whole multiple of it.")
def fmu(model_path, output_path, input_name, mass, time_step):
    """An FMI 2.0 co-simulation FMU of the model, for Modelica tools and Simulink.

    Built with PythonFMU: the FMU runs polind in the Python it finds where
    it is simulated, so that Python needs polind and PythonFMU installed
    (the FMU carries a requirements.txt naming both). Writes F.fmu.
    """
    if input_name == "x":
        for option, value in (("--mass", mass), ("--time-step", time_step)):
            if value is not None:
                raise InputError(f"The '{option}' option is for a body's FMU; expected it "
                                 f"with '--input force' only.")
    mass = 1.0 if mass is None else mass
    time_step = 1e-3 if time_step is None else time_step
    for option, value in (("--mass", mass), ("--time-step", time_step)):
        if not 0.0 < value < float("inf"):
            raise InputError(f"The '{option}' option must be a positive finite number. "
                             f"Got {value!r} instead.")
    refuse_overwriting_inputs([model_path], {"--output": output_path})
    check_output_path(output_path)
    model = load_model(model_path)
    try:
        from polind.fmu import build_fmu
        build_fmu(model, output_path, input=input_name, mass=mass, time_step=time_step)
    except ImportError as error:
        raise InputError(f"'polind fmu' needs PythonFMU ({error}); expected it installed: "
                         f"pip install polind[fmu].") from None
    click.echo(f"wrote {output_path}: an FMI 2.0 co-simulation FMU ({model.type}, input "
               f"{input_name})", err=os.fspath(output_path) == "-")
