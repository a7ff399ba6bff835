"""The coverage one sensing step adds (eq. 2–3), in integer arithmetic only: the same ticks on every CPU.

A sensing event (a robot's pose at the start of a step) is turned into ticks by every replica of the map
(issue 13's event form of a delta, protocol/README.md). The float kernel (:func:`model.world.wedge.sense_wedge`)
stays the model: libm's cos, sin and atan2 may differ in their last bit between CPUs and libraries, so
replicas fed with events must not use it. This kernel uses int64 additions, shifts, comparisons and
multiplications that never overflow, and nothing else after the event's numbers are read:

1. Inputs to fixed point. x, y and the cell side in Q40 (units·2⁴⁰, rounded: multiplying a float64 by a
   power of two is exact, rounding it to an integer is too); θ in Q60 radians, wrapped into [−π, π] with
   the integer 2π. The scenario's constants R, F and C = α_M·dt·2²⁰/(R·F) (the ticks of eq. 2–3 per
   unit·radian) are made exact integers once, from the float64 values, by rational arithmetic.
2. The window: every cell whose centre may lie within R of (x, y), by integer floor and ceiling division,
   clipped to the grid.
3. Each cell centre in the robot's frame, (along, across) = K·R(−θ)·(c − p): CORDIC rotation (Volder 1959)
   by −θ of the window's first centre and of one column and one row step, ``ITERATIONS`` shift-and-add
   steps each; every other centre by adding steps (exact). Positions in Q``p`` (``p`` from R: no overflow).
4. φ = |θ_i − θ_x| and r: CORDIC vectoring of (along, |across|), 20 steps, then the angle left taken as
   y/x and the length as x + y²/(2x) (both within 1e-17), one integer division.
   A centre within 2⁻⁴⁵ units of the robot is under it: r = φ = 0 (eq. 2 leaves θ_ix undefined there; the
   float kernel takes 0 too).
5. In the wedge (r ≤ R and φ ≤ F), ticks = ⌊C·(R − r)·(F − φ) + ½⌋ as in eq. 2–3, with the products taken
   through 31-bit limbs (:func:`_mul_high`); outside, 0.

It agrees with the float kernel's rounding on all but a few cells per hundred thousand (both round a real
number to the nearest tick and each errs by far less than 10⁻⁵ tick; a cell whose exact value lies that
close to a half tick may round either way, as do cells the float kernel leaves out for occlusion): the
sender lists those cells beside the event, so every replica gets the sender's ticks exactly
(:mod:`protocol.events`).
"""

from __future__ import annotations

import math
from fractions import Fraction
from typing import NamedTuple

import numpy as np
from numba import njit

from model.paper.fixed_point import COVERAGE_SCALE

ITERATIONS = 44
"""CORDIC steps: the angle left after them is below atan(2⁻⁴³) ≈ 1.1e-13 rad (≈ 1e-6 tick)."""

ATAN_Q60 = np.array(
    [
        905502432259640355,
        534549298976576474,
        282441168888798124,
        143371547418228444,
        71963988336308046,
        36017075762092179,
        18012932708689205,
        9007016009513623,
        4503576721087964,
        2251796950380271,
        1125899548928887,
        562949908682076,
        281474971118251,
        140737487656277,
        70368744090283,
        35184372077909,
        17592186043051,
        8796093022037,
        4398046511083,
        2199023255549,
        1099511627776,
        549755813888,
        274877906944,
        137438953472,
        68719476736,
        34359738368,
        17179869184,
        8589934592,
        4294967296,
        2147483648,
        1073741824,
        536870912,
        268435456,
        134217728,
        67108864,
        33554432,
        16777216,
        8388608,
        4194304,
        2097152,
        1048576,
        524288,
        262144,
        131072,
    ],
    dtype=np.int64,
)
"""atan(2⁻ⁱ) in Q60 radians, i = 0..43, rounded from 60-digit decimal series (written out, not computed
with the platform's libm, so every machine holds the same table)."""
PI_Q60 = 3622009729038561421
"""π in Q60."""
INV_K2_Q62 = 1700587475451006561
"""2⁶²/(K₄₄·K₂₀), K_n = Π_{i<n} sqrt(1 + 4⁻ⁱ) the CORDIC gain of n steps: rotation takes 44, vectoring 20
(60-digit decimal products, written out)."""
VECTOR_ITERATIONS = 20
"""Vectoring steps; the angle left, below 2⁻¹⁹, is then taken as y/x (its cube, under 1e-17 rad, dropped)."""

POSITION_BITS = 40
"""Absolute positions in Q40 (domains and ranges up to 2²⁰ units: :func:`exact_kernel` refuses more)."""
TICK_BITS = 20
"""Ticks are computed in Q20 and then rounded to the nearest tick."""
LIMB = 31
TWO_TO_40, TWO_TO_60 = float(2**40), float(2**60)
COARSE_SHIFT = 33
CONE_SLACK = 1 << 36
"""The cone pre-test's slack: coarse coordinates times Q30 constants err by under 2³², so a cell it rejects
lies well outside the wedge (more than 2⁶·2^(33 − p)/r rad)."""


class ExactKernel(NamedTuple):
    """The scenario's constants of the integer kernel (:func:`exact_kernel`): the same on every replica."""

    rows: int
    cols: int
    cell_q40: int  # cell side, Q40
    range_q40: int  # R, Q40
    bits: int  # p: positions relative to the robot in Qp
    range_qp: int  # R, Qp
    half_angle_q60: int  # F, Q60 radians
    gain_q: int  # round(C·2^(84 − p)), C = α_M·dt·2²⁰/(R·F): ticks per unit·radian


def _round(value: Fraction) -> int:
    return math.floor(value + Fraction(1, 2))


def exact_kernel(
    rows: int, cols: int, cell: float, sensing_range: float, half_angle: float, alpha_max: float, dt: float
) -> ExactKernel:
    """The kernel's integers from the scenario's float64 constants, exactly (rational arithmetic)."""
    # Positions relative to the robot reach (R + 2 cells)·√2 in the window, times K² ≈ 2.72 in CORDIC:
    # keep that under 2⁶² so no sum overflows int64.
    reach = (sensing_range + 2.0 * cell) * math.sqrt(2.0) * 2.72
    bits = min(62 - math.ceil(math.log2(reach)), 60)
    longest = max(sensing_range + 2.0 * cell, (max(rows, cols) + 2) * cell)
    if bits < 20 or longest >= 2.0**20:
        raise ValueError("the exact coverage kernel needs a sensing range and a domain under 2^20 units")
    gain = Fraction(alpha_max) * Fraction(dt) * COVERAGE_SCALE / (Fraction(sensing_range) * Fraction(half_angle))
    gain_q = _round(gain * 2 ** (84 - bits))
    if not 0 < gain_q < 2**62:
        raise ValueError("the exact coverage kernel needs alpha_max·dt/(R·F) in range")
    return ExactKernel(
        rows,
        cols,
        _round(Fraction(cell) * 2**POSITION_BITS),
        _round(Fraction(sensing_range) * 2**POSITION_BITS),
        bits,
        _round(Fraction(sensing_range) * 2**bits),
        _round(Fraction(half_angle) * 2**60),
        gain_q,
    )


@njit(cache=True)
def _mul_high(a: int, b: int) -> int:
    """⌊a·b / 2⁶²⌋ for 0 ≤ a, b < 2⁶², through 31-bit limbs (every partial product < 2⁶²)."""
    mask = (1 << LIMB) - 1
    a1, a0 = a >> LIMB, a & mask
    b1, b0 = b >> LIMB, b & mask
    middle = a1 * b0 + a0 * b1 + ((a0 * b0) >> LIMB)
    return a1 * b1 + (middle >> LIMB)


@njit(cache=True)
def _to_q40(value: float) -> int:
    return math.floor(value * TWO_TO_40 + 0.5)


@njit(cache=True)
def _rotate(x: int, y: int, turn: np.ndarray) -> tuple[int, int]:
    """Rotate (x, y) by the angle whose CORDIC directions are ``turn`` (its first entry: quarter turns)."""
    quarters = turn[0]
    if quarters == 1:
        x, y = -y, x
    elif quarters == -1:
        x, y = y, -x
    for i in range(ITERATIONS):
        if turn[i + 1] > 0:
            x, y = x - (y >> i), y + (x >> i)
        else:
            x, y = x + (y >> i), y - (x >> i)
    return x, y


@njit(cache=True)
def _directions(angle_q60: int) -> np.ndarray:
    """The CORDIC rotation directions for an angle in Q60 radians within [−π, π]: a quarter turn first
    (−1, 0, 1) when |angle| > π/2, then ITERATIONS signs."""
    turn = np.zeros(ITERATIONS + 1, dtype=np.int64)
    half_pi = PI_Q60 >> 1
    z = angle_q60
    if z > half_pi:
        turn[0], z = 1, z - half_pi
    elif z < -half_pi:
        turn[0], z = -1, z + half_pi
    for i in range(ITERATIONS):
        if z >= 0:
            turn[i + 1], z = 1, z - ATAN_Q60[i]
        else:
            turn[i + 1], z = -1, z + ATAN_Q60[i]
    return turn


@njit(cache=True)
def _vector(along: int, across: int) -> tuple[int, int]:
    """(K₂₀·|(along, across)|, atan2(across, along)) for across ≥ 0 and along ≥ 0, angle in Q60.

    VECTOR_ITERATIONS steps leave (x, y) with |y/x| < 2⁻¹⁹; then atan(y/x) ≈ y/x and |(x, y)| ≈ x + y²/(2x),
    each within 1e-17 of its value: t = y/x in Q40 by one division of 62-bit integers."""
    x, y, z = along, across, 0
    for i in range(VECTOR_ITERATIONS):
        if y > 0:
            x, y, z = x + (y >> i), y - (x >> i), z + ATAN_Q60[i]
        else:
            x, y, z = x - (y >> i), y + (x >> i), z - ATAN_Q60[i]
    if x <= 0:
        return 0, z
    scale = x >> 20
    if scale == 0:  # a vector this short (under 2⁻³⁵ units) is at the robot: no angle left to refine
        return x, z
    ratio = (y << 20) // scale  # y/x in Q40 (|y| < 2⁴³ so y·2²⁰ fits)
    return x + ((y * (ratio >> 10)) >> 31), z + (ratio << 20)


@njit(cache=True)
def event_window(kernel: ExactKernel, x: float, y: float) -> tuple[int, int, int, int]:
    """[row0, row1) × [col0, col1): the cells whose centres may lie within R of (x, y), clipped to the grid."""
    x40, y40 = _to_q40(x), _to_q40(y)
    half = kernel.cell_q40 >> 1
    cell, reach = kernel.cell_q40, kernel.range_q40
    col0 = -((-(x40 - reach - half)) // cell)  # ceil
    col1 = (x40 + reach - half) // cell + 1
    row0 = -((-(y40 - reach - half)) // cell)
    row1 = (y40 + reach - half) // cell + 1
    return max(row0, 0), min(max(row1, 0), kernel.rows), max(col0, 0), min(max(col1, 0), kernel.cols)


@njit(cache=True)
def event_ticks(kernel: ExactKernel, x: float, y: float, theta: float) -> tuple[int, int, np.ndarray]:
    """(row0, col0, ticks): the coverage of eq. 3 a step sensed from (x, y, θ) adds, in integers."""
    row0, row1, col0, col1 = event_window(kernel, x, y)
    ticks = np.zeros((max(row1 - row0, 0), max(col1 - col0, 0)), dtype=np.int64)
    if ticks.size == 0:
        return row0, col0, ticks
    # θ in Q60 within [−π, π]: reduce a float first when it is far out (deterministic float steps).
    two_pi = 6.283185307179586
    if abs(theta) > 4.0:
        theta = theta - two_pi * math.floor(theta / two_pi + 0.5)
    angle = math.floor(theta * TWO_TO_60 + 0.5)
    while angle > PI_Q60:
        angle -= 2 * PI_Q60
    while angle < -PI_Q60:
        angle += 2 * PI_Q60
    turn = _directions(-angle)  # into the robot's frame: rotate by −θ
    shift = POSITION_BITS - kernel.bits  # Q40 → Qp
    half = kernel.cell_q40 >> 1
    first_x = (2 * col0 + 1) * half - _to_q40(x)
    first_y = (2 * row0 + 1) * half - _to_q40(y)
    if shift >= 0:
        first_x, first_y, step = first_x >> shift, first_y >> shift, kernel.cell_q40 >> shift
    else:
        first_x, first_y, step = first_x << -shift, first_y << -shift, kernel.cell_q40 << -shift
    base_along, base_across = _rotate(first_x, first_y, turn)
    col_along, col_across = _rotate(step, 0, turn)
    row_along, row_across = _rotate(0, step, turn)
    reach = kernel.range_qp
    # Cheap tests first, in coarse units of 2^(33 − p) (every K-scaled coordinate of the window is under
    # 2^61.3 by the choice of p, so coarse ones are under 2^28.3 and their products with Q30 constants under
    # 2^59): K·r ≤ K·R < 1.6875·R, and (F < π/2) the centre within the cone, |across|·cos F ≤ along·sin F,
    # with a slack far above the shifts' error; the exact test decides every cell they let through.
    coarse = COARSE_SHIFT
    limit = (reach >> coarse) * 27 // 16 + 4
    narrow = kernel.half_angle_q60 < (PI_Q60 >> 1)
    under = 1 << max(kernel.bits - 45, 0)  # a centre this near (2⁻⁴⁵ units) is under the robot: r = θ_ix = 0
    cos_f, sin_f = _rotate(1 << 30, 0, _directions(kernel.half_angle_q60))
    for i in range(ticks.shape[0]):
        along = base_along + i * row_along
        across = base_across + i * row_across
        for j in range(ticks.shape[1]):
            a, c = along >> coarse, across >> coarse
            if a * a + c * c <= limit * limit and (not narrow or (a > -4 and abs(c) * cos_f - a * sin_f <= CONE_SLACK)):
                if abs(along) <= under and abs(across) <= under:  # the robot stands on this centre
                    distance, bearing = 0, 0
                else:
                    distance, bearing = _vector(abs(along), abs(across))
                    if along < 0:
                        bearing = PI_Q60 - bearing
                    distance = _mul_high(distance, INV_K2_Q62)  # K²·r → r
                if distance <= reach and bearing <= kernel.half_angle_q60:
                    spread = _mul_high(reach - distance, kernel.half_angle_q60 - bearing)  # Q(p − 2)
                    value = _mul_high(spread, kernel.gain_q)  # Q20
                    ticks[i, j] = (value + (1 << (TICK_BITS - 1))) >> TICK_BITS
            along += col_along
            across += col_across
    return row0, col0, ticks


def load_kernels(kernel: ExactKernel | None) -> None:
    """Have numba load this kernel now (from its cache after the first run), so a process's first event
    does not pay for it (see model.step.load_kernels)."""
    if kernel is not None:
        event_ticks(kernel, 0.0, 0.0, 0.0)
