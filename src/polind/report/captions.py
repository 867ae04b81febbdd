"""What the report says about each phenomenon: its title, what to see, its figures.

:data:`TITLES`, :data:`DESCRIPTIONS` and :data:`FIGURES`, each by the keys
of :data:`polind.phenomena.PHENOMENA <polind.phenomena.common.PHENOMENA>`.
The figures (:mod:`polind.report.figures`) take their titles from here;
``metrics.json`` (:mod:`polind.report.summary`) and ``report.html``
(:mod:`polind.report.page`) their descriptions and the names of the
figure files.
"""

from __future__ import annotations

from polind.phenomena import MEMORY_TOLERANCE

__all__ = ["TITLES", "DESCRIPTIONS", "FIGURES"]

#: The heading of each phenomenon, in the figures and on the page.
TITLES = {
    "stribeck": "Stribeck effect",
    "presliding_memory": "Presliding hysteresis with non-local memory",
    "frictional_lag": "Sliding hysteresis (frictional lag)",
    "non_drifting": "Non-drifting under an oscillating force below break-away",
    "stick_slip": "Stick-slip",
    "breakaway": "Break-away force versus force rate",
}

#: One sentence per phenomenon: what the figure shows and what to look for.
DESCRIPTIONS = {
    "stribeck": "Each model slides at constant velocities from 1e-3 vs to 1e3 vs until its "
                "force is steady (markers); the line is the analytic steady curve "
                "g(v) + sigma2 v. Look for the dip from the static level Fs at low velocity "
                "down to the Coulomb level Fc, and for the markers sitting on the line. "
                "Maxwell-slip is rate independent: its steady force is flat.",
    "presliding_memory": "The displacement goes to +A (virgin curve), back to -A, then through "
                         "loops nested inside that major loop, all within the presliding "
                         "range. Where a loop comes back to the reversal point it started "
                         "from, an open circle marks a loop that closes there (its force "
                         f"equals the force the path had at that point, within "
                         f"{MEMORY_TOLERANCE:g} of the loop's span) and a square one that "
                         "does not, the gap dotted. "
                         "With non-local memory (the Maxwell-slip family) every loop closes, "
                         "is wiped out, and the path continues on the branch it would have "
                         "followed without the loop (dashed). LuGre's loops do not close.",
    "frictional_lag": "The velocity oscillates as v0 + va sin(2 pi f t), always positive; each "
                      "loop is the force over one period at one frequency, the dashed line "
                      "the steady curve. Look for loops that circulate clockwise in this "
                      "plane, as the arrows show (the force is higher while the velocity "
                      "rises than while it falls), shrink onto the steady curve as f falls "
                      "and open up as f rises. Maxwell-slip has no loop.",
    "non_drifting": "A body pushed by 0.5 Fc + 0.4 Fc sin(2 pi t), always below break-away. "
                    "The curve is its position, the dots the mean position of each cycle. "
                    "The Maxwell-slip family shakes down: the cycle means stop moving. LuGre "
                    "creeps forward by the same step every cycle (Dupont et al. 2002).",
    "stick_slip": "A body pulled through a spring at a constant drive velocity; the curves are "
                  "the spring force. Left: from rest, the set-up of Canudas de Wit et al. "
                  "(1995), m = 1 kg, k_d = 2 N/m, v_d = 0.1 m/s, scaled to each model's "
                  "force level (m and k_d times Fc / 1 N, v_d = 100 vs): LuGre with the "
                  "1995 parameters runs it as published, the other models a heavier body on a "
                  "stiffer spring (each panel's title gives m and k_d). Middle and right: "
                  "the body starts in steady sliding with a stiffer spring; at the low drive "
                  "velocity (on the falling branch of the Stribeck curve) sliding is unstable "
                  "and grows into a periodic stick-slip cycle, at the high one it stays "
                  "steady. Maxwell-slip, with no velocity weakening, never stick-slips.",
    "breakaway": "The applied force rises at a constant rate from zero; the body has broken "
                 "away when its velocity reaches the threshold (vs). Left: the applied force at "
                 "break-away over Fs, per rate. Right: the velocity of the subject model's body "
                 "against the applied force for each rate. Look for break-away at Fs for slow "
                 "ramps, and for how it moves with the rate.",
}

#: PNG files of each phenomenon (the first is the phenomenon's main figure).
FIGURES = {
    "stribeck": ("stribeck.png",),
    "presliding_memory": ("presliding_memory.png",),
    "frictional_lag": ("frictional_lag.png",),
    "non_drifting": ("non_drifting.png",),
    "stick_slip": ("stick_slip.png", "stick_slip_reference.png"),
    "breakaway": ("breakaway.png",),
}
