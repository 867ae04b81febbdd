"""The reference loops ``polind bench`` measures the models against; no model uses them.

Two kinds, both written from the user guide's equations, not from the
kernels:

* plain NumPy loops (``numpy_*``): the step loop in Python, the elements
  vectorised, as one would write a model without numba; their forces are
  compared with the kernel's, so both sides demonstrably do the same work;
* bare numba loops (``bare_*``, :func:`plain_gms`): what a user would write by
  hand for one model and one kind of motion, with nothing else (no
  validation, no path preparation, no state object); the ratio rows
  (:mod:`polind.bench.ratios`) time :func:`polind.simulate` and
  :class:`polind.Stepper` against them.
"""

from __future__ import annotations

import math

import numpy as np

from polind.kernels import jit
from polind.models.static import stribeck_curve


# --- plain NumPy loops (step loop in Python, elements vectorised) -------------------------

def _with_viscous(out, sigma2, path):
    """``out + sigma2 v`` at each sample's velocity (the kernels' viscous term)."""
    out += sigma2 * path.sample_velocity
    return out


def numpy_maxwell_slip(path, stiffness, breakaway, sigma2=0.0):
    """Maxwell-slip (:ref:`guide-maxwell-slip`): ``F_i <- clip(F_i + k_i dx, -W_i, W_i)``."""
    force = np.zeros_like(stiffness)
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    for k in range(1, path.t.shape[0]):
        force = np.clip(force + stiffness * path.displacement[k], -breakaway, breakaway)
        out[k] = force.sum()
    return _with_viscous(out, sigma2, path)


def numpy_gms(path, stiffness, weight, attraction, fc, fs, vs, delta, sigma2=0.0):
    """GMS (:ref:`guide-gms`): a stuck element follows ``k_i dx``, a slipping one relaxes
    exactly towards ``sgn(v) alpha_i g(v)``."""
    force = np.zeros_like(stiffness)
    slip = np.zeros_like(stiffness)
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    for k in range(1, path.t.shape[0]):
        v = path.step_velocity[k]
        if v == 0.0:
            out[k] = force.sum()
            continue
        g = stribeck_curve(v, fc, fs, vs, delta)
        direction = np.sign(v)
        capacity = weight * g
        target = direction * capacity
        relaxed = target + (force - target) * np.exp(-attraction * path.step[k] / (weight * g))
        trial = force + stiffness * path.displacement[k]
        slipping = (slip == direction) | (direction * force >= capacity)
        crosses = direction * trial >= capacity
        force = np.where(slipping, relaxed, np.where(crosses, target, trial))
        slip = np.where(slipping | crosses, direction, 0.0)
        out[k] = force.sum()
    return _with_viscous(out, sigma2, path)


def numpy_lugre(path, sigma0, sigma1, fc, fs, vs, delta, sigma2=0.0):
    """LuGre (:ref:`guide-lugre`) with the exact exponential step of its state ``z``."""
    z = 0.0
    out = np.empty(path.t.shape[0])
    for k in range(path.t.shape[0]):
        if k > 0 and path.step_velocity[k] != 0.0:
            v = path.step_velocity[k]
            g = stribeck_curve(v, fc, fs, vs, delta)
            steady = np.sign(v) * g / sigma0
            z = steady + (z - steady) * np.exp(-sigma0 * abs(v) * path.step[k] / g)
        v = path.sample_velocity[k]
        g = stribeck_curve(v, fc, fs, vs, delta)
        out[k] = sigma0 * z + sigma1 * (v - sigma0 * abs(v) * z / g)
    return _with_viscous(out, sigma2, path)


def numpy_dahl(path, sigma0, fc):
    """Dahl (:ref:`guide-dahl`) with exponent 1: exact exponential approach to ``sgn(dx) Fc``."""
    force = 0.0
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    for k in range(1, path.t.shape[0]):
        dx = path.displacement[k]
        if dx != 0.0:
            s = np.sign(dx)
            force = s * fc - (s * fc - force) * np.exp(-sigma0 * abs(dx) / fc)
        out[k] = force
    return out


def numpy_leuven(path, stiffness, breakaway, exponent, sigma1, fc, fs, vs, delta, sigma2=0.0):
    """Backward Euler on the Leuven state equation (:ref:`guide-leuven`), brentq per step."""
    from scipy.optimize import brentq

    force = np.zeros_like(stiffness)
    out = np.empty(path.t.shape[0])
    out[0] = 0.0
    bound = breakaway.sum()
    for k in range(1, path.t.shape[0]):
        v, h = path.step_velocity[k], path.step[k]
        dz = 0.0
        if v != 0.0:
            s = np.sign(v) * stribeck_curve(v, fc, fs, vs, delta)

            def residual(increment):
                r = np.clip(force + stiffness * increment, -breakaway, breakaway).sum() / s
                return increment - v * h * (1.0 - np.sign(r) * abs(r) ** exponent)

            reach = abs(v * h) * (1.0 + (bound / abs(s)) ** exponent) * 1.000001
            dz = brentq(residual, -reach, reach, xtol=1e-300, rtol=1e-15)
        force = np.clip(force + stiffness * dz, -breakaway, breakaway)
        out[k] = force.sum() + sigma1 * dz / h
    return _with_viscous(out, sigma2, path)


def numpy_stribeck(path, fc, fs, vs, delta, sigma2):
    """The Stribeck curve (:ref:`guide-stribeck-curve`) and viscous friction at each sample."""
    out = np.empty(path.t.shape[0])
    for k in range(path.t.shape[0]):
        v = path.sample_velocity[k]
        out[k] = np.sign(v) * stribeck_curve(v, fc, fs, vs, delta) + sigma2 * v
    return out


# --- which loop is a model's reference ---------------------------------------------------

def _curve(p):
    return [p[key] for key in ("coulomb_force", "static_force", "stribeck_velocity",
                               "stribeck_exponent")]


def _gms_loop(p):
    stiffness, weight = np.array(p["stiffness"]), np.array(p["weight"])
    return lambda path: numpy_gms(path, stiffness, weight, p["attraction"], *_curve(p),
                                  sigma2=p["viscous_coefficient"])


def _maxwell_slip_loop(p):
    stiffness, breakaway = np.array(p["stiffness"]), np.array(p["breakaway_force"])
    return lambda path: numpy_maxwell_slip(path, stiffness, breakaway, p["viscous_coefficient"])


def _leuven_loop(p):
    stiffness, breakaway = np.array(p["stiffness"]), np.array(p["breakaway_force"])
    return lambda path: numpy_leuven(path, stiffness, breakaway, p["exponent"],
                                     p["bristle_damping"], *_curve(p),
                                     sigma2=p["viscous_coefficient"])


def _lugre_loop(p):
    return lambda path: numpy_lugre(path, p["bristle_stiffness"], p["bristle_damping"],
                                    *_curve(p), sigma2=p["viscous_coefficient"])


def _dahl_loop(p):
    return lambda path: numpy_dahl(path, p["stiffness"], p["coulomb_force"])


def _stribeck_loop(p):
    return lambda path: numpy_stribeck(path, *_curve(p), p["viscous_coefficient"])


#: The plain NumPy loop of each model type, as ``prepare(model) -> reference(path) ->
#: forces`` (``prepare`` reads the parameters once, outside the timing).  At its constant
#: load Pol-Ind is the GMS of its element table (:ref:`guide-pol-ind-law`), so its loop is
#: GMS's on its equivalent GMS parameters; iwan4 is the Maxwell-slip of its element table.
NUMPY_REFERENCES = {
    "maxwell-slip": lambda model: _maxwell_slip_loop(model.params),
    "gms": lambda model: _gms_loop(model.params),
    "pol-ind": lambda model: _gms_loop(model.equivalent_gms().params),
    "iwan4": lambda model: _maxwell_slip_loop(model.to_maxwell_slip().params),
    "leuven": lambda model: _leuven_loop(model.params),
    "lugre": lambda model: _lugre_loop(model.params),
    "dahl": lambda model: _dahl_loop(model.params),
    "stribeck": lambda model: _stribeck_loop(model.params),
}


def numpy_reference(model):
    """The plain NumPy loop of ``model``, ready to run (``reference(path)`` gives the forces
    at the path's samples), or None if :data:`NUMPY_REFERENCES` has none for its type."""
    prepare = NUMPY_REFERENCES.get(model.type)
    return None if prepare is None else prepare(model)


# --- bare numba loops, compiled with the kernels' own numba options (polind.kernels.jit) ---

@jit
def bare_call(value):
    """The cheapest Python-to-numba call: one float in, the same float out."""
    return value


@jit
def bare_maxwell_slip(x, stiffness, slip, z, out):
    """Maxwell-slip on positions: ``z_i = clip(z_i + dx, -D_i, D_i)``, ``F = sum k_i z_i``."""
    out[0] = 0.0
    for k in range(1, x.shape[0]):
        dx = x[k] - x[k - 1]
        force = 0.0
        for i in range(z.shape[0]):
            zi = min(max(z[i] + dx, -slip[i]), slip[i])
            z[i] = zi
            force += stiffness[i] * zi
        out[k] = force


@jit
def bare_lugre(t, x, sigma0, sigma1, sigma2, fc, fs, vs, out):
    """LuGre's exact exponential step (:ref:`guide-lugre`) on positions, Stribeck exponent 2.

    ``z <- z_ss + (z - z_ss) exp(-sigma0 |v| h / g(v))``, ``z_ss = sgn(v) g(v) / sigma0``,
    ``F = sigma0 z + sigma1 dz/dt + sigma2 v`` with ``dz/dt = v - sigma0 |v| z / g(v)``.
    """
    z = 0.0
    for k in range(1, x.shape[0]):
        h = t[k] - t[k - 1]
        v = (x[k] - x[k - 1]) / h
        ratio = v / vs
        g = fc + (fs - fc) * math.exp(-ratio * ratio)
        if v != 0.0:
            steady = (g if v > 0.0 else -g) / sigma0
            z = steady + (z - steady) * math.exp(-sigma0 * abs(v) * h / g)
        out[k] = sigma0 * z + sigma1 * (v - sigma0 * abs(v) * z / g) + sigma2 * v


@jit
def plain_gms(t, x, stiffness, weight, attraction, fc, fs, vs, delta, force, slip, out):
    """GMS (:ref:`guide-gms`) as first written: a branch per element, math.exp per slipping one.

    A stuck element follows ``F_i + k_i dx`` until it reaches ``alpha_i g(v)``
    (then it sits there and slips); a slipping one relaxes exactly,
    ``T + (F_i - T) exp(-C h / (alpha_i g))``, ``T = sgn(v) alpha_i g(v)``.
    """
    out[0] = 0.0
    for k in range(1, x.shape[0]):
        h = t[k] - t[k - 1]
        dx = x[k] - x[k - 1]
        v = dx / h
        total = 0.0
        if v == 0.0:
            for i in range(force.shape[0]):
                total += force[i]
            out[k] = total
            continue
        g = fc + (fs - fc) * math.exp(-abs(v / vs) ** delta)
        direction = 1.0 if v > 0.0 else -1.0
        for i in range(force.shape[0]):
            capacity = weight[i] * g
            target = direction * capacity
            f = force[i]
            if slip[i] == direction or direction * f >= capacity:
                f = target + (f - target) * math.exp(-attraction * h / capacity)
                slip[i] = direction
            else:
                f = f + stiffness[i] * dx
                if direction * f >= capacity:
                    f = target
                    slip[i] = direction
                else:
                    slip[i] = 0.0
            force[i] = f
            total += f
        out[k] = total
