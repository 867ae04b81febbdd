"""polind fmu: FMI 2.0 co-simulation FMUs, run by FMPy, against Stepper and Body (issue 23).

``polind fmu MODEL --output F.fmu`` builds the FMU with PythonFMU; FMPy runs
it in a separate Python (the FMU's slave runs polind in the Python that
loads it), driven as a co-simulation master drives it.  The input-``x`` FMU
gives at each communication point the force ``Stepper.advance`` returns
for that point's ``x``; the input-``force`` FMU gives the ``Body`` after the
step over which the force was held.  Both equal the Python objects to
1e-12 (measured: bit for bit), for the default Pol-Ind model and LuGre.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest

pytest.importorskip("pythonfmu")
fmpy = pytest.importorskip("fmpy")

import polind  # noqa: E402
from polind.cli import _run  # noqa: E402
from polind.models import LuGre, PolInd  # noqa: E402

from conftest import assert_close  # noqa: E402

EXAMPLES = {"pol-ind": PolInd.example, "lugre": LuGre.example}
H = 1e-3           # communication step [s]
N = 400            # communication points

#: The master, run in its own Python: ``python DRIVER spec.json out.json``.  It uses the
#: model once before it loads the FMU, so that numba's compiled code is loaded outside the
#: FMU's calls (PythonFMU 0.7: a library loaded for the first time inside them can leave
#: the heap corrupted at process exit; the guide, "An FMU").
DRIVER = r'''
import json, sys
import numpy as np
import polind
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

spec = json.load(open(sys.argv[1]))
model = polind.model_from_dict(json.load(open(spec["model"])))
if spec["input"] == "x":
    polind.Stepper(model).advance(1e-3, x=1e-9)
else:
    polind.Body(model, spec["mass"], spec["time_step"]).step(0.0)
description = read_model_description(spec["fmu"])
refs = {v.name: v.valueReference for v in description.modelVariables}
fmu = FMU2Slave(guid=description.guid, unzipDirectory=extract(spec["fmu"]),
                modelIdentifier=description.coSimulation.modelIdentifier, instanceName="polind")
fmu.instantiate()
t, h = spec["t"], spec["h"]
fmu.setupExperiment(startTime=t[0])
fmu.enterInitializationMode()
for name, value in spec.get("parameters", {}).items():
    fmu.setReal([refs[name]], [value])
fmu.exitInitializationMode()
out = {}
if spec["input"] == "x":
    forces = []
    for k, x in enumerate(spec["x"]):
        fmu.setReal([refs["x"]], [x])                      # the input at t_k,
        forces.append(fmu.getReal([refs["F"]])[0])         # the output it gives there,
        fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=h)   # then on
    out["F"] = forces
else:
    rows = [fmu.getReal([refs["x"], refs["v"], refs["F"]])]
    for k, force in enumerate(spec["force"]):
        fmu.setReal([refs["force"]], [force])
        fmu.doStep(currentCommunicationPoint=t[k], communicationStepSize=h)
        rows.append(fmu.getReal([refs["x"], refs["v"], refs["F"]]))
    out["xvF"] = rows
    if spec.get("bad_step"):
        try:
            fmu.doStep(currentCommunicationPoint=t[-1] + h, communicationStepSize=0.7 * h)
            out["bad_step"] = "ok"
        except Exception as error:
            out["bad_step"] = str(error)
fmu.terminate()
fmu.freeInstance()
json.dump(out, open(sys.argv[2], "w"))
'''


def _model_file(tmp_path, model):
    path = tmp_path / f"{model.type}.json"
    path.write_text(model.to_json())
    return path


def _build(tmp_path, model, *options):
    """``polind fmu`` on the command line (in this process); the FMU's path."""
    out = tmp_path / f"{model.type}-{'-'.join(options) or 'x'}.fmu"
    assert _run(["fmu", str(_model_file(tmp_path, model)), "--output", str(out),
                 *options]) == 0
    return out


def _drive(tmp_path, spec):
    """Run the master in a fresh Python; its results."""
    driver = tmp_path / "driver.py"
    driver.write_text(DRIVER)
    spec_path, out_path = tmp_path / "spec.json", tmp_path / "out.json"
    spec_path.write_text(json.dumps(spec))
    done = subprocess.run([sys.executable, str(driver), str(spec_path), str(out_path)],
                          capture_output=True, text=True, timeout=600, env=os.environ.copy())
    assert done.returncode == 0, done.stderr[-3000:]
    return json.loads(out_path.read_text())


def _scale(values):
    return max(float(np.max(np.abs(values))), 1e-300)


@pytest.mark.parametrize("model_type", list(EXAMPLES))
def test_the_position_fmu_is_the_stepper(tmp_path, model_type):
    model = EXAMPLES[model_type]()
    fmu = _build(tmp_path, model)
    t = H * np.arange(N)
    amplitude = 3.0 * model.characteristic_scales()["presliding_range"]
    x = amplitude * np.sin(2 * np.pi * 4.0 * t) * (1.0 + t)
    got = np.array(_drive(tmp_path, {"fmu": str(fmu), "model": str(_model_file(tmp_path, model)),
                                     "input": "x", "t": t.tolist(), "h": H,
                                     "x": x.tolist()})["F"])
    # The FMU's point k is the master's t[k-1] plus the step: the Stepper at those times.
    stepper = polind.Stepper(model, position=float(x[0]))
    expected = [stepper.force] + [stepper.advance(float(t[k - 1] + H), x=float(x[k]))
                                  for k in range(1, N)]
    np.testing.assert_array_equal(got, expected)
    # ... and at the master's own times t[k], to rounding
    stepper = polind.Stepper(model, position=float(x[0]))
    at_t = [stepper.force] + [stepper.advance(float(t[k]), x=float(x[k])) for k in range(1, N)]
    assert_close(got, at_t, 1e-12, _scale(at_t), f"{model_type} FMU, input x")
    assert np.ptp(got) > model.characteristic_scales()["coulomb_force"]     # it slid


@pytest.mark.parametrize("model_type", list(EXAMPLES))
def test_the_force_fmu_is_the_body(tmp_path, model_type):
    model = EXAMPLES[model_type]()
    mass, time_step, inner = 2.0, 2.5e-4, 4          # four Body steps per communication step
    fmu = _build(tmp_path, model, "--input", "force", "--mass", "3.0",
                 "--time-step", str(time_step))
    t = H * np.arange(N)
    level = model.characteristic_scales()["static_force"]
    force = 1.6 * level * np.sin(2 * np.pi * 3.0 * t)
    # the FMU's parameter mass (built with 3 kg) set to 2 kg before the run; after it,
    # LuGre's FMU is given a step that is not a multiple of the time step (0.7 ms against
    # 0.25 ms), which it refuses
    refuse = model_type == "lugre"
    out = _drive(tmp_path, {
        "fmu": str(fmu), "model": str(_model_file(tmp_path, model)), "input": "force",
        "mass": mass, "time_step": time_step, "t": t.tolist(), "h": H,
        "force": force.tolist(), "parameters": {"mass": mass}, "bad_step": refuse})
    rows = np.array(out["xvF"])
    body = polind.Body(model, mass=mass, time_step=time_step)
    expected = [(body.position, body.velocity, body.friction)]
    for value in force:
        for _ in range(inner):
            body.step(float(value))
        expected.append((body.position, body.velocity, body.friction))
    expected = np.array(expected)
    np.testing.assert_array_equal(rows, expected)
    assert np.max(np.abs(expected[:, 1])) > 1e-3                             # it slid
    if refuse:
        assert "fmi2DoStep failed" in out["bad_step"]


def test_the_fmu_describes_itself(tmp_path):
    model = LuGre.example()
    position_fmu = _build(tmp_path, model)
    position = fmpy.read_model_description(str(position_fmu))
    body = fmpy.read_model_description(str(_build(tmp_path, model, "--input", "force")))
    assert position.fmiVersion == body.fmiVersion == "2.0"
    assert position.coSimulation.modelIdentifier == "PolindFriction"
    assert body.coSimulation.modelIdentifier == "PolindBody"
    assert [(v.name, v.causality) for v in position.modelVariables] == [
        ("x", "input"), ("F", "output")]
    assert [(v.name, v.causality) for v in body.modelVariables] == [
        ("mass", "parameter"), ("time_step", "parameter"), ("force", "input"),
        ("x", "output"), ("v", "output"), ("F", "output")]
    assert position.coSimulation.canHandleVariableCommunicationStepSize
    assert not body.coSimulation.canHandleVariableCommunicationStepSize
    with zipfile.ZipFile(position_fmu) as archive:
        config = json.loads(archive.read("resources/polind_fmu.json"))
        requirements = archive.read("resources/requirements.txt").decode()
    assert polind.model_from_dict(config["model"]) == model
    assert "polind" in requirements and "pythonfmu" in requirements


@pytest.mark.parametrize("arguments, match", [
    (["--input", "y"], "'y' is not one of"),
    (["--mass", "2"], "'--mass' option is for a body's FMU"),
    (["--input", "force", "--time-step", "0"], "'--time-step' option must be a positive"),
    (["--input", "force", "--mass", "-1"], "'--mass' option must be a positive"),
])
def test_bad_options_exit_2_with_one_line(tmp_path, capsys, arguments, match):
    model_path = _model_file(tmp_path, LuGre.example())
    out = tmp_path / "out.fmu"
    assert _run(["fmu", str(model_path), "--output", str(out), *arguments]) == 2
    error = capsys.readouterr().err
    assert error.count("\n") == 1 and error.startswith("polind: error:")
    assert match in error
    assert not out.exists()


def test_the_output_must_not_be_the_model_file(tmp_path, capsys):
    model_path = _model_file(tmp_path, LuGre.example())
    assert _run(["fmu", str(model_path), "--output", str(model_path)]) == 2
    assert "is also an input" in capsys.readouterr().err
    assert polind.load_model(model_path) == LuGre.example()


def test_build_fmu_refuses_bad_arguments(tmp_path):
    from polind.fmu import build_fmu

    with pytest.raises(polind.InputError, match="'input' of build_fmu"):
        build_fmu(LuGre.example(), tmp_path / "a.fmu", input="v")
    with pytest.raises(polind.InputError, match="'mass'"):
        build_fmu(LuGre.example(), tmp_path / "a.fmu", input="force", mass=0.0)
    with pytest.raises(polind.InputError, match="friction model"):
        build_fmu("lugre", tmp_path / "a.fmu")
    assert not (tmp_path / "a.fmu").exists()
