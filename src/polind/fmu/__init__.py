"""A polind model as an FMI 2.0 co-simulation FMU: :func:`build_fmu` (``polind fmu``).

The user guide, :ref:`guide-fmu`.  The FMU is built with PythonFMU
(https://github.com/NTNU-IHB/PythonFMU): its binary runs a Python class
(``polind.fmu.slave.FrictionSlave``) inside the Python interpreter of
the process that simulates it, or of the Python it finds there; **polind
and PythonFMU must be installed in that Python** (the FMU carries a
``requirements.txt`` naming both, which ``pythonfmu deploy -f F.fmu``
installs).  Binaries for Linux (x86-64) and Windows (x86-64) come with
PythonFMU.

PythonFMU is an optional dependency: ``pip install polind[fmu]``.
``import polind`` never imports this package.
"""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

from polind.errors import InputError, describe
from polind.stepper import check_model
from polind.validation import check_number

__all__ = ["build_fmu", "fmu_bytes", "MODEL_IDENTIFIERS"]

#: The FMU's model identifier (the name of its binary and class) for each input.
MODEL_IDENTIFIERS = {"x": "PolindFriction", "force": "PolindBody"}

_SCRIPT = '''"""A polind FMU (written by polind fmu): the model is resources/{config}."""

from polind.fmu.slave import FrictionSlave


class {identifier}(FrictionSlave):
    """{what}"""
'''

_WHAT = {"x": "A polind friction model: input x [m], output F [N] (polind.Stepper).",
         "force": "A body with polind friction: input force [N], outputs x, v, F (polind.Body)."}


def build_fmu(model, path, input="x", mass=1.0, time_step=1e-3) -> Path:
    """Write an FMI 2.0 co-simulation FMU of ``model`` to ``path``.

    Parameters
    ----------
    model : FrictionModel
        Any polind model (a registered model of your own needs its package
        where the FMU runs, as polind itself); stored in the FMU as its
        model file.
    path : str or Path
        The ``.fmu`` file to write, atomically (:func:`polind.io.atomic_write_bytes`:
        a file appears only once it is complete; ``-`` is standard output).
    input : {"x", "force"}, default "x"
        ``"x"``: input the position ``x`` [m], output the friction force
        ``F`` [N], as :meth:`polind.Stepper.advance` at each communication
        point.  ``"force"``: input the applied ``force`` [N], outputs
        ``x`` [m], ``v`` [m/s] and ``F`` [N], a :class:`polind.Body` after
        the communication step over which the force was held.
    mass : float, default 1
        m [kg] of the body (``"force"`` only; the FMU's parameter ``mass``).
    time_step : float, default 1e-3
        h [s], the body's step (``"force"`` only; the FMU's parameter
        ``time_step``): a communication step must be a whole multiple of it.

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ImportError
        Without PythonFMU (``pip install polind[fmu]``).

    Examples
    --------
    >>> import polind
    >>> from polind.fmu import build_fmu
    >>> model = polind.model_from_dict({"model": {"type": "dahl", "stiffness": 1e5,
    ...                                           "coulomb_force": 1.0}})
    >>> build_fmu(model, "dahl.fmu")                          # doctest: +SKIP
    PosixPath('dahl.fmu')
    """
    from polind import io

    data = fmu_bytes(model, input, mass, time_step)
    io.atomic_write_bytes(path, data)
    return Path(path)


def fmu_bytes(model, input="x", mass=1.0, time_step=1e-3) -> bytes:
    """The FMU of :func:`build_fmu` as bytes (a zip archive), built in a temporary directory."""
    check_model(model, "build_fmu")
    if not isinstance(input, str) or input not in MODEL_IDENTIFIERS:
        raise InputError(f"The 'input' of build_fmu must be 'x' (position in, force out) or "
                         f"'force' (force in; x, v, F out). Got {describe(input)} instead.")
    mass = check_number("build_fmu", "mass", mass, "positive")
    time_step = check_number("build_fmu", "time_step", time_step, "positive")
    try:
        from pythonfmu import FmuBuilder
    except ImportError as error:
        raise ImportError("polind.fmu needs PythonFMU: pip install polind[fmu]") from error
    from polind.fmu.slave import CONFIG

    identifier = MODEL_IDENTIFIERS[input]
    config = {"polind_fmu": 1, "model": model.to_dict(), "input": input, "mass": mass,
              "time_step": time_step}
    with tempfile.TemporaryDirectory(prefix="polind_fmu_") as folder:
        work = Path(folder)
        script = work / f"{identifier}.py"
        script.write_text(_SCRIPT.format(config=CONFIG, identifier=identifier,
                                         what=_WHAT[input]), encoding="utf-8")
        (work / CONFIG).write_text(json.dumps(config, allow_nan=False, indent=1),
                                   encoding="utf-8")
        (work / "requirements.txt").write_text("polind\npythonfmu>=0.7\n", encoding="utf-8")
        # A body's FMU steps in whole multiples of its time step only.
        options = {"canHandleVariableCommunicationStepSize": input == "x"}
        built = FmuBuilder.build_FMU(script, dest=work / "out.fmu",
                                     project_files=[work / CONFIG, work / "requirements.txt"],
                                     **options)
        return Path(built).read_bytes()
