"""Each model's runner module, generated from the one template (:mod:`polind.kernels.template`).

``python -m polind.kernels.generate`` writes ``polind/kernels/generated/<name>.py``
for every entry of :data:`MODELS`: a header that binds the template's
placeholders to the model's functions, then the template's source below its
marker, unchanged.  The files are committed (numba keeps a function in its
on-disk cache only when it has a source file), and a test checks that they
are what this module writes.  :func:`runners_for` gives the runners of any
model's functions: polind's own from those files, a user's model (its
functions not among :data:`MODELS`) from the same source compiled in
memory, once per process.
"""

from __future__ import annotations

import functools
import importlib
import sys
from pathlib import Path
from types import SimpleNamespace

KERNELS = Path(__file__).resolve().parent
TEMPLATE = KERNELS / "template.py"
GENERATED = KERNELS / "generated"
MARKER = "# --- template: every line below is copied into each generated module ---\n"

#: ``load`` of a model whose state does not follow the normal load
#: (:func:`polind.kernels.contract.no_load_change`).
NO_LOAD_CHANGE = "no_load_change"

#: Each runner module: the kernel module its functions come from, and each
#: placeholder's function there (``settled`` and ``path_step`` default to
#: ``step``, ``load`` to ``force``; ``trial``, ``blocks`` and ``block`` to none).
MODELS = {
    "memoryless": ("polind.kernels.static", {
        "step": "memoryless_step", "force": "memoryless_force",
        "tangent": "memoryless_tangent", "load": NO_LOAD_CHANGE}),
    "dahl": ("polind.kernels.single", {
        "step": "dahl_step", "force": "dahl_force", "tangent": "dahl_tangent",
        "load": NO_LOAD_CHANGE}),
    "lugre": ("polind.kernels.single", {
        "step": "lugre_step", "force": "lugre_force", "tangent": "lugre_tangent",
        "blocks": "lugre_blocks", "block": "lugre_block", "load": NO_LOAD_CHANGE}),
    "leuven": ("polind.kernels.single", {
        "step": "leuven_step", "force": "leuven_force", "tangent": "leuven_tangent",
        "load": NO_LOAD_CHANGE}),
    "maxwell_slip": ("polind.kernels.elements", {
        "step": "maxwell_slip_step", "force": "maxwell_slip_force",
        "tangent": "maxwell_slip_tangent", "blocks": "maxwell_slip_blocks",
        "block": "maxwell_slip_block", "trial": "maxwell_slip_trial_step",
        "load": NO_LOAD_CHANGE}),
    "gms": ("polind.kernels.elements", {
        "step": "gms_step", "force": "gms_force", "tangent": "gms_tangent",
        "trial": "gms_trial_step", "load": NO_LOAD_CHANGE}),
    "pol_ind": ("polind.kernels.pol_ind", {
        "step": "pol_ind_step", "force": "pol_ind_force", "tangent": "pol_ind_tangent",
        "settled": "settled_step", "trial": "pol_ind_trial_step"}),
    "pol_ind_fixed_load": ("polind.kernels.pol_ind_fixed", {
        "step": "fixed_load_step", "force": "fixed_load_force", "tangent": "pol_ind_tangent",
        "trial": "fixed_load_trial_step", "path_step": "fixed_load_path_step",
        "load": NO_LOAD_CHANGE}),
    "pol_ind_plastic": ("polind.kernels.pol_ind_plastic", {
        "step": "plastic_step", "force": "plastic_force", "tangent": "pol_ind_tangent",
        "settled": "plastic_settled_step", "trial": "pol_ind_trial_step"}),
}

_PLACEHOLDERS = ("step", "force", "tangent", "settled", "path_step", "load")


def template_body() -> str:
    """The template's source below its marker."""
    text = TEMPLATE.read_text(encoding="utf-8")
    return text[text.index(MARKER) + len(MARKER):]


def render(name: str) -> str:
    """The source of the runner module ``name`` (a key of :data:`MODELS`)."""
    module, functions = MODELS[name]
    functions = {"settled": functions["step"], "path_step": functions["step"],
                 "load": functions["force"], **functions}
    lines = [f'"""The runners of {name} ({module}), generated from polind.kernels.template.',
             "",
             "Do not edit: ``python -m polind.kernels.generate`` writes this file again.",
             '"""',
             "",
             "from polind.kernels import jit"]
    if "block" in functions:
        lines.append(f"from {module} import {functions['blocks']} as model_blocks")
        lines.append(f"from {module} import {functions['block']} as model_block")
    else:
        lines.append("from polind.kernels.contract import no_block as model_block")
        lines.append("from polind.kernels.contract import no_blocks as model_blocks")
    if "trial" in functions:
        lines.append(f"from {module} import {functions['trial']} as model_trial")
    else:
        lines.append("from polind.kernels.contract import no_trial as model_trial")
    for placeholder in _PLACEHOLDERS:
        source = ("polind.kernels.contract" if functions[placeholder] == NO_LOAD_CHANGE
                  else module)
        lines.append(f"from {source} import {functions[placeholder]} as model_{placeholder}")
    return "\n".join(lines) + "\n" + template_body()


def write_all() -> list[Path]:
    """Write every runner module; return the files that changed."""
    GENERATED.mkdir(exist_ok=True)
    changed = []
    init = GENERATED / "__init__.py"
    init_text = ('"""The runner modules of polind\'s models, generated by '
                 'polind.kernels.generate: do not edit."""\n')
    for path, text in [(init, init_text)] + [(GENERATED / f"{name}.py", render(name))
                                             for name in MODELS]:
        if not path.exists() or path.read_text(encoding="utf-8") != text:
            path.write_text(text, encoding="utf-8")
            changed.append(path)
    return changed


def _own(functions) -> str | None:
    """The runner module of polind's own ``(step, force, tangent)``, or None."""
    step, force, tangent = functions
    for name, (module, names) in MODELS.items():
        if {"step", "force", "tangent"} <= names.keys():
            kernels = sys.modules.get(module)
            if kernels is not None and (getattr(kernels, names["step"], None) is step
                                        and getattr(kernels, names["force"], None) is force
                                        and getattr(kernels, names["tangent"], None)
                                        is tangent):
                return name
    return None


@functools.lru_cache(maxsize=None)
def _compiled(step, force, tangent):
    """The template compiled for a user's functions (not cached on disk)."""
    from polind.kernels import jit
    from polind.kernels.contract import no_block, no_blocks, no_trial

    namespace = {"__name__": "polind.kernels.template_for_" + getattr(step, "__name__", "model"),
                 "jit": functools.partial(jit, cache=False),
                 "model_step": step, "model_force": force, "model_tangent": tangent,
                 "model_settled": step, "model_path_step": step, "model_load": force,
                 "model_blocks": no_blocks,
                 "model_block": no_block,
                 "model_trial": no_trial}
    exec(compile(template_body(), str(TEMPLATE), "exec"), namespace)    # noqa: S102
    return SimpleNamespace(**{key: value for key, value in namespace.items()
                              if not key.startswith("__")})


def runners_for(step, force, tangent, runners=None):
    """The runner module of a model's functions (see the module notes).

    ``runners`` is the name of a module of :data:`MODELS` (a model of
    polind's own names its own, which may bind another ``settled`` step);
    without it the functions are looked up there, and a user's functions get
    the template compiled for them in this process.
    """
    name = runners or _own((step, force, tangent))
    if name is not None:
        return importlib.import_module(f"polind.kernels.generated.{name}")
    return _compiled(step, force, tangent)


if __name__ == "__main__":
    for changed_path in write_all():
        print(f"wrote {changed_path}")
