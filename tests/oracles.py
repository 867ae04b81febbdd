"""Plain reference implementations of the friction models (MODELS.md 0-6).

These are the independent check on polind's fast kernels (STYLE.md: "test
oracles beside the fast code"). They are written from the specification,
for clarity and not for speed: plain Python loops over samples and elements,
the exact per-step updates MODELS.md prescribes, and closed forms where the
specification gives one.

The sampling contract is INTERFACE.md's ``simulate``:

* exactly one of ``x`` and ``v``;
* with ``x`` the step from ``t[k]`` to ``t[k+1]`` has the velocity
  ``(x[k+1] - x[k]) / (t[k+1] - t[k])`` and ``v[k]`` is the velocity of the
  step that ends at sample ``k`` (``v[0]`` the first step's);
* with ``v`` the sample velocities are ``v`` itself, each step's velocity is
  the mean of its end samples, its displacement the trapezoid, and ``x`` is
  the trapezoidal integral from 0;
* stateful models integrate each step at the step's velocity; the force at
  sample ``k`` is the model output after step ``k`` evaluated with ``v[k]``
  for the velocity-proportional terms; at sample 0 the state is zero.

``simulate(model, t, x=..., v=...)`` takes the same model dictionaries as
``polind.model_from_dict`` (with or without the outer ``{"model": ...}``) and
returns an :class:`OracleResult` holding ``t, x, v, force`` and, for the
element models, the per-sample internal state.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp

__all__ = [
    "DEFAULTS",
    "pol_ind_varying_load",
    "OracleResult",
    "dahl_closed_form",
    "dahl_reference_integration",
    "dahl_step",
    "masing_branch",
    "motion",
    "params",
    "sgn",
    "simulate",
    "stribeck_curve",
    "virgin_curve",
]

#: Defaults of optional keys (INTERFACE.md; the brief's table).
DEFAULTS = {
    "coulomb": {},
    "stribeck": {"stribeck_exponent": 2.0, "viscous_coefficient": 0.0,
                 "stribeck_shape": "exponential"},
    "dahl": {"exponent": 1.0},
    "lugre": {"stribeck_exponent": 2.0, "viscous_coefficient": 0.0,
              "stribeck_shape": "exponential"},
    "maxwell-slip": {"viscous_coefficient": 0.0},
    "gms": {"stribeck_exponent": 2.0, "viscous_coefficient": 0.0,
            "stribeck_shape": "exponential"},
    "leuven": {"stribeck_exponent": 2.0, "viscous_coefficient": 0.0,
               "stribeck_shape": "exponential"},
}


# ---------------------------------------------------------------------------
# Closed forms
# ---------------------------------------------------------------------------

def sgn(value: float) -> float:
    """Sign with ``sgn(0) = 0`` (MODELS.md 0)."""
    return 1.0 if value > 0 else (-1.0 if value < 0 else 0.0)


def stribeck_curve(v, coulomb_force, static_force, stribeck_velocity,
                   stribeck_exponent=2.0, stribeck_shape="exponential"):
    """The Stribeck curve ``g(v)`` of MODELS.md 0 (both shapes); vectorised."""
    a = np.abs(np.asarray(v, dtype=float) / stribeck_velocity) ** stribeck_exponent
    if stribeck_shape == "exponential":
        decay = np.exp(-a)
    elif stribeck_shape == "rational":
        decay = 1.0 / (1.0 + a)
    else:
        raise ValueError(f"unknown stribeck_shape {stribeck_shape!r}")
    g = coulomb_force + (static_force - coulomb_force) * decay
    return float(g) if np.ndim(g) == 0 else g


def virgin_curve(x, stiffness, breakaway_force):
    """Maxwell-slip virgin curve ``phi(x) = sgn(x) sum_i k_i min(|x|, D_i)``."""
    k = np.asarray(stiffness, dtype=float)
    w = np.asarray(breakaway_force, dtype=float)
    d = w / k
    x = np.asarray(x, dtype=float)
    out = np.sign(x) * np.sum(k * np.minimum(np.abs(x)[..., None], d), axis=-1)
    return float(out) if out.ndim == 0 else out


def masing_branch(x, x_r, f_r, stiffness, breakaway_force):
    """Masing rule: ``F(x) = F_r - 2 phi((x_r - x) / 2)`` after a reversal."""
    return f_r - 2.0 * virgin_curve((x_r - np.asarray(x, dtype=float)) / 2.0,
                                    stiffness, breakaway_force)


def dahl_closed_form(x, x0, f0, direction, stiffness, coulomb_force):
    """Dahl, ``alpha = 1``, monotone motion from ``(x0, F0)`` (MODELS.md 2)."""
    x = np.asarray(x, dtype=float)
    target = direction * coulomb_force
    return target - (target - f0) * np.exp(-stiffness * np.abs(x - x0) / coulomb_force)


def dahl_step(force, dx, stiffness, coulomb_force, exponent):
    """Exact Dahl update over a monotone displacement ``dx``.

    In the path length ``s = |x - x0|`` the variable ``u = 1 - F sgn(v)/Fc``
    obeys ``du/ds = -(sigma0/Fc) |u|^alpha sgn(u)``, which separates:
    ``alpha = 1`` exponential; ``alpha < 1`` (including 0) ``|u|^(1-alpha)``
    falls linearly and ``u`` stays 0 once reached; ``alpha > 1``
    ``|u|^(1-alpha)`` grows linearly. The sign of ``u`` is kept.
    """
    direction = sgn(dx)
    if direction == 0.0:
        return force
    c = stiffness / coulomb_force
    dist = abs(dx)
    u0 = 1.0 - force * direction / coulomb_force
    mag0, s_u = abs(u0), sgn(u0)
    if mag0 == 0.0:
        mag = 0.0
    elif exponent == 1.0:
        mag = mag0 * math.exp(-c * dist)
    elif exponent < 1.0:
        q = mag0 ** (1.0 - exponent) - (1.0 - exponent) * c * dist
        mag = q ** (1.0 / (1.0 - exponent)) if q > 0.0 else 0.0
    else:
        q = mag0 ** (1.0 - exponent) + (exponent - 1.0) * c * dist
        mag = q ** (-1.0 / (exponent - 1.0))
    u = s_u * mag
    return direction * coulomb_force * (1.0 - u)


def dahl_reference_integration(force, dx, stiffness, coulomb_force, exponent,
                               rtol=1e-12):
    """Dahl over a monotone ``dx`` by ``solve_ivp`` on ``dF/dx`` (a check of
    :func:`dahl_step`, independent of the separable solution)."""
    direction = sgn(dx)
    if direction == 0.0:
        return force

    def u_of(f):
        return 1.0 - f * direction / coulomb_force

    def rhs(_, f):
        # in the path length s = |x - x0|: dF/ds = sgn(v) dF/dx
        u = u_of(f[0])
        return [direction * stiffness * abs(u) ** exponent * sgn(u)]

    def reaches_target(_, f):       # u = 0: F = sgn(v) Fc, where it then stays
        return u_of(f[0])

    reaches_target.terminal = True
    if u_of(force) == 0.0:
        return force
    sol = solve_ivp(rhs, (0.0, abs(dx)), [force], method="DOP853", rtol=rtol,
                    atol=1e-14 * coulomb_force, events=reaches_target)
    if sol.status == 1:             # the event fired (only possible for alpha < 1)
        return direction * coulomb_force
    return float(sol.y[0, -1])


# ---------------------------------------------------------------------------
# Parameters and motion
# ---------------------------------------------------------------------------

def params(model: dict) -> dict:
    """Inner model dict with the defaults of optional keys filled in."""
    inner = dict(model["model"]) if "model" in model else dict(model)
    out = dict(DEFAULTS.get(inner["type"], {}))
    out.update(inner)
    return out


@dataclass
class Motion:
    """A sampled motion under the ``simulate`` contract."""

    t: np.ndarray
    x: np.ndarray          # sample positions
    v: np.ndarray          # sample velocities (res.v)
    step_v: np.ndarray     # velocity of each step k -> k+1
    step_dx: np.ndarray    # displacement of each step
    step_h: np.ndarray     # duration of each step


def motion(t, x=None, v=None) -> Motion:
    """Apply the INTERFACE.md sampling contract to ``t`` and ``x`` or ``v``."""
    t = np.asarray(t, dtype=float)
    if (x is None) == (v is None):
        raise ValueError("exactly one of x and v")
    h = np.diff(t)
    if x is not None:
        x = np.asarray(x, dtype=float)
        dx = np.diff(x)
        step_v = dx / h
        sample_v = np.concatenate([step_v[:1], step_v])
        return Motion(t, x.copy(), sample_v, step_v, dx, h)
    v = np.asarray(v, dtype=float)
    step_v = 0.5 * (v[:-1] + v[1:])
    dx = step_v * h
    xs = np.concatenate([[0.0], np.cumsum(dx)])
    return Motion(t, xs, v.copy(), step_v, dx, h)


@dataclass
class OracleResult:
    t: np.ndarray
    x: np.ndarray
    v: np.ndarray
    force: np.ndarray
    #: per-sample internal state: "z" (lugre, leuven), "element_force"
    #: (maxwell-slip, gms, leuven hysteresis), "slipping" (gms)
    states: dict = field(default_factory=dict)


def _g(p, v):
    return stribeck_curve(v, p["coulomb_force"], p["static_force"],
                          p["stribeck_velocity"], p["stribeck_exponent"],
                          p["stribeck_shape"])


# ---------------------------------------------------------------------------
# Steppers, one per model
# ---------------------------------------------------------------------------

def _coulomb(p, m):
    force = np.array([p["coulomb_force"] * sgn(v) for v in m.v])
    return OracleResult(m.t, m.x, m.v, force)


def _stribeck(p, m):
    force = np.array([_g(p, v) * sgn(v) + p["viscous_coefficient"] * v for v in m.v])
    return OracleResult(m.t, m.x, m.v, force)


def _dahl(p, m):
    n = len(m.t)
    force = np.zeros(n)
    f = 0.0
    for k in range(n - 1):
        f = dahl_step(f, m.step_dx[k], p["stiffness"], p["coulomb_force"], p["exponent"])
        force[k + 1] = f
    return OracleResult(m.t, m.x, m.v, force)


def _lugre(p, m):
    s0, s1, s2 = p["bristle_stiffness"], p["bristle_damping"], p["viscous_coefficient"]
    n = len(m.t)
    z = 0.0
    zs = np.zeros(n)

    def output(z, v):
        dzdt = v - s0 * abs(v) * z / _g(p, v)
        return s0 * z + s1 * dzdt + s2 * v

    force = np.zeros(n)
    force[0] = output(z, m.v[0])
    for k in range(n - 1):
        vk, h = m.step_v[k], m.step_h[k]
        if vk != 0.0:
            g = _g(p, vk)
            z_ss = sgn(vk) * g / s0
            z = z_ss + (z - z_ss) * math.exp(-s0 * abs(vk) * h / g)
        zs[k + 1] = z
        force[k + 1] = output(z, m.v[k + 1])
    return OracleResult(m.t, m.x, m.v, force, {"z": zs})


def _maxwell_slip(p, m):
    k = np.asarray(p["stiffness"], dtype=float)
    w = np.asarray(p["breakaway_force"], dtype=float)
    d = w / k
    s2 = p["viscous_coefficient"]
    n = len(m.t)
    z = np.zeros(len(k))
    elements = np.zeros((n, len(k)))
    force = np.zeros(n)
    force[0] = s2 * m.v[0]
    for j in range(n - 1):
        z = np.clip(z + m.step_dx[j], -d, d)
        elements[j + 1] = k * z
        force[j + 1] = float(np.sum(k * z)) + s2 * m.v[j + 1]
    return OracleResult(m.t, m.x, m.v, force, {"element_force": elements})


def _iwan4(p, m):
    """The density of MODELS.md 12 cut into the cells polind grades (their edges are the
    one choice taken from polind: ``innermost_edge`` and equal ratios above it), each cell
    one element with the cell's integrals of rho and rho phi, the point mass one more;
    then stepped as Maxwell-slip."""
    from polind.models.iwan4 import innermost_edge

    fs, kt, chi, beta = p["slip_force"], p["stiffness"], p["chi"], p["beta"]
    n = p.get("elements", 64)
    r = (chi + 1) / (chi + 2)
    phi_max = fs * (1 + beta) / (kt * (beta + r))
    big_r = fs * (chi + 1) / (phi_max ** (chi + 2) * (beta + r))
    point = fs / phi_max * beta / (beta + r)
    cells = n - 1 if beta > 0 else n
    first = innermost_edge(chi, cells)
    edges = [0.0] + [phi_max * first ** (1 - j / (cells - 1)) for j in range(cells)] \
        if cells > 1 else [0.0, phi_max]
    stiffness, breakaway = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        stiffness.append(big_r * (b ** (chi + 1) - a ** (chi + 1)) / (chi + 1))
        breakaway.append(big_r * (b ** (chi + 2) - a ** (chi + 2)) / (chi + 2))
    if beta > 0:
        stiffness.append(point)
        breakaway.append(point * phi_max)
    return _maxwell_slip({"stiffness": stiffness, "breakaway_force": breakaway,
                          "viscous_coefficient": 0.0}, m)


def _gms(p, m):
    k = [float(a) for a in p["stiffness"]]
    alpha = [float(a) for a in p["weight"]]
    c = p["attraction"]
    s2 = p["viscous_coefficient"]
    n, ne = len(m.t), len(k)
    fi = [0.0] * ne
    slipping = [False] * ne
    slip_dir = [0.0] * ne
    elements = np.zeros((n, ne))
    modes = np.zeros((n, ne), dtype=bool)
    force = np.zeros(n)
    force[0] = s2 * m.v[0]
    for j in range(n - 1):
        v, h, dx = m.step_v[j], m.step_h[j], m.step_dx[j]
        if v != 0.0:            # v = 0: dF_i/dt = 0 in both modes
            direction = sgn(v)
            g = _g(p, v)
            for i in range(ne):
                target = alpha[i] * direction * g        # T = alpha_i s(v)
                if slipping[i] and slip_dir[i] != direction:
                    slipping[i] = False                  # v changed sign: stick
                slip_time = 0.0
                if slipping[i]:
                    slip_time = h
                elif (fi[i] - target) * direction >= 0.0:
                    # |F_i| >= alpha_i g(v) with F_i v > 0 at the step start
                    slipping[i], slip_dir[i], slip_time = True, direction, h
                else:
                    stuck = fi[i] + k[i] * dx
                    if (stuck - target) * direction >= 0.0:
                        # the crossing splits the step: stick up to T, then slip
                        crossing = (target - fi[i]) / (k[i] * v)
                        fi[i] = target
                        slipping[i], slip_dir[i] = True, direction
                        slip_time = max(h - crossing, 0.0)
                    else:
                        fi[i] = stuck
                if slip_time > 0.0:
                    fi[i] = target + (fi[i] - target) * math.exp(
                        -c * slip_time / (alpha[i] * g))
        elements[j + 1] = fi
        modes[j + 1] = slipping
        force[j + 1] = sum(fi) + s2 * m.v[j + 1]
    return OracleResult(m.t, m.x, m.v, force,
                        {"element_force": elements, "slipping": modes})


def _leuven_step(z0, deflections, v, h, k, d, s, n_exp, rtol):
    """Integrate ``dz/dt = v (1 - sgn(r)|r|^n)``, ``r = Fh(z)/s``, over one step.

    ``z`` is monotone inside a step (a scalar autonomous ODE cannot turn), so
    along the step the hysteresis force is the branch
    ``Fh(z) = sum_i k_i clip(z_i0 + z - z0, -D_i, D_i)`` of the element
    deflections at the step start: exact Maxwell-slip bookkeeping.
    """
    def hysteresis(dz):
        return float(np.sum(k * np.clip(deflections + dz, -d, d)))

    def rhs(_, y):
        r = hysteresis(y[0]) / s
        return [v * (1.0 - sgn(r) * abs(r) ** n_exp)]

    scale = float(np.max(d))
    sol = solve_ivp(rhs, (0.0, h), [0.0], method="LSODA", rtol=rtol,
                    atol=1e-13 * scale)
    if not sol.success:  # pragma: no cover - a broken reference is a test error
        raise RuntimeError(sol.message)
    dz = float(sol.y[0, -1])
    return z0 + dz, np.clip(deflections + dz, -d, d)


def _leuven(p, m, rtol=1e-11):
    k = np.asarray(p["stiffness"], dtype=float)
    w = np.asarray(p["breakaway_force"], dtype=float)
    d = w / k
    s1, s2, n_exp = p["bristle_damping"], p["viscous_coefficient"], p["exponent"]
    n = len(m.t)
    z = 0.0
    deflections = np.zeros(len(k))
    zs = np.zeros(n)
    elements = np.zeros((n, len(k)))
    force = np.zeros(n)
    # Sample 0: zero state; no step has ended there, so the mean dz/dt term
    # is taken as 0 (the brief leaves it open; tests do not rely on it).
    force[0] = s2 * m.v[0]
    for j in range(n - 1):
        v, h = m.step_v[j], m.step_h[j]
        z_old = z
        if v != 0.0:
            s = sgn(v) * _g(p, v)
            z, deflections = _leuven_step(z, deflections, v, h, k, d, s, n_exp, rtol)
        zs[j + 1] = z
        elements[j + 1] = k * deflections
        mean_dzdt = (z - z_old) / h
        force[j + 1] = float(np.sum(k * deflections)) + s1 * mean_dzdt + s2 * m.v[j + 1]
    return OracleResult(m.t, m.x, m.v, force, {"z": zs, "element_force": elements})


STEPPERS = {
    "coulomb": _coulomb,
    "stribeck": _stribeck,
    "dahl": _dahl,
    "lugre": _lugre,
    "maxwell-slip": _maxwell_slip,
    "gms": _gms,
    "leuven": _leuven,
    "iwan4": _iwan4,
}


#: How closely each model's kernel follows its stepper above on the conformance motion
#: (relative to the largest force): the exact updates to rounding; Leuven's kernel
#: discretises z at first order in time (user guide, "Leuven"), so it is compared by
#: its convergence as the step shrinks (tests/test_models_leuven.py), not here (None).
AGREEMENT = {"leuven": None}


def simulate(model: dict, t, x=None, v=None, **options) -> OracleResult:
    """Reference run of ``model`` (a model dict) on the motion ``t``, ``x``|``v``."""
    p = params(model)
    return STEPPERS[p["type"]](p, motion(t, x=x, v=v), **options)


def pol_ind_varying_load(t, x, load, heights, root_weights, separation_at, g_star, mu_s, mu_k,
                         stribeck_velocity=1e-3, attraction=1e4, element_law=None,
                         count_scale=None):
    """Plain stepper of the Pol-Ind law under a time-varying normal load (positions ``x``).

    The elements are fixed in height (``heights``); at every sample the
    separation is ``separation_at(load[k])``, each element in contact has
    stiffness ``8 G* w_j sqrt(delta_j)`` and capacity share ``alpha_j``
    proportional to ``w_j delta_j^(3/2)`` (``w_j = n_j sqrt(R_j)``, the
    ``root_weights``), forces are clipped to ``alpha_j mu_s N``, an element out
    of contact (or just back) restarts stuck at zero, and the GMS rule with
    ``g(v) = N [mu_k + (mu_s - mu_k) exp(-(v / vs)^2)]`` advances the rest.
    ``element_law(delta)``, if given, returns the stiffnesses and the loads
    (any common scale) of the elements at the interferences ``delta`` instead
    (elastic-plastic asperities).  ``count_scale(N)``, if given, multiplies
    every element's asperity count at the load ``N`` (a ball on a flat,
    whose nominal area follows the load).
    """
    force_el = np.zeros(heights.size)
    slipping = np.zeros(heights.size)
    in_contact = np.ones(heights.size, dtype=bool)
    out = np.zeros(t.size)
    for k in range(t.size):
        d = separation_at(load[k])
        delta = np.maximum(heights - d, 0.0)
        if element_law is None:
            stiffness = 8 * g_star * root_weights * np.sqrt(delta)
            breakaway = root_weights * delta ** 1.5
        else:
            stiffness, breakaway = element_law(delta)
        if count_scale is not None:
            stiffness = stiffness * count_scale(load[k])
            breakaway = breakaway * count_scale(load[k])
        alpha = breakaway / breakaway.sum()
        capacity = alpha * mu_s * load[k]
        now = delta > 0
        force_el = np.clip(force_el, -capacity, capacity)
        slipping[~now | (now & ~in_contact)] = 0.0     # out of contact, or new: stuck at 0
        in_contact = now
        if k > 0:
            h = t[k] - t[k - 1]
            v = (x[k] - x[k - 1]) / h
            if v != 0:
                g = load[k] * (mu_k + (mu_s - mu_k) * math.exp(-(v / stribeck_velocity) ** 2))
                direction = np.sign(v)
                for j in range(heights.size):
                    if alpha[j] == 0.0:
                        force_el[j] = 0.0
                        continue
                    target = direction * alpha[j] * g
                    if slipping[j] != direction:
                        slipping[j] = 0.0
                    if slipping[j] == 0.0 and direction * force_el[j] < alpha[j] * g:
                        trial = force_el[j] + stiffness[j] * v * h
                        if direction * trial >= alpha[j] * g:
                            force_el[j], slipping[j] = target, direction
                        else:
                            force_el[j] = trial
                    else:
                        slipping[j] = direction
                        force_el[j] = target + (force_el[j] - target) * math.exp(
                            -attraction * h / (alpha[j] * g))
        out[k] = force_el.sum()
    return out
