"""Model files the safety tests write: one text of a direct-summation Pol-Ind model."""


def direct_pol_ind(*, heights_file="heights.csv", normal_load=1.0, model_lines="", surface="",
                   fit=""):
    """A Pol-Ind model file on measured summit heights (``heights_file``, relative to it).

    ``model_lines`` are more keys of ``[model]``; ``surface`` more lines of
    ``[model.surface]`` (a ``topography`` instead of ``heights_file = None``);
    ``fit`` a ``[fit]`` table.
    """
    heights = "" if heights_file is None else f'heights_file = "{heights_file}"\n'
    return f"""[model]
type = "pol-ind"
normal_load = {normal_load!r}
static_coefficient = 0.15
kinetic_coefficient = 0.10
stribeck_velocity = 1e-3
attraction = 1e4
{model_lines}
[model.surface]
{'' if surface.startswith('topography') else 'asperity_radius = 50e-6'}
{surface}
[model.materials]
youngs_modulus = [210e9, 210e9]
poisson_ratio = [0.3, 0.3]

[model.discretisation]
summation = "direct"
{heights}
{fit}"""
