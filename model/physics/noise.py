"""What a robot believes of its pose (issue 37, item 2): wheel odometry that drifts, a localiser's late and
noisy fixes, and commands that reach the wheels late.

- **Odometry**: each period the belief moves by the true motion of the period (in the robot's own frame:
  forward, sideways, turn), plus Gaussian drift of σ ``odometry_per_metre`` per unit travelled (forward and
  sideways) and ``odometry_per_radian`` per radian turned.
- **Localiser**: every 1 / ``localiser_rate`` time units it measures the true pose with σ
  ``localiser_sigma`` (x, y) and ``localiser_heading_deg``; the fix arrives ``localiser_latency`` later, the
  odometry since then is replayed on it (what a ROS 2 robot's localisation does with a late fix and the
  odom → base_link transform), and the belief moves toward it by the Kalman gain (:func:`fix_gains`).
- **Fusion**: the belief keeps its own variance, grown by the odometry's drift as the robot travels and
  turns (:func:`predicted_variance`) and shrunk by each fix. A fix that replaced the belief whole put its σ
  into every pose: a robot standing at a station faced bearings from a pose that jumped by σ at every fix,
  so it swung its heading by up to 18° (two rooms and a door, σ 0.05, its bearing carrot 0.15 away) and its
  stares fell short. Fused, a robot that stands still holds its belief still; a robot that drives is held
  to its fixes as much as its odometry drifts.
- **Commands** reach the wheels ``command_latency`` later, whole periods (:class:`CommandDelay`).
- **Covering what is believed is not covering what is true**: a camera a little off its believed pose puts a
  cell's coverage partly on its neighbours, and a team that believes every cell has Λ* leaves some short in
  truth. So with noise the team covers its own map to (1 + ``cover_margin``) Λ*, by default
  :data:`model.scenario.physics_keys.COVER_MARGIN`, and the run is judged against Λ* by the true poses (``true_coverage``).

Every draw comes from one generator seeded by the scenario's seed, in a fixed order: a run repeats exactly.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, replace

import numpy as np

from model.scenario import Scenario
from model.scenario.physics_keys import cover_margin_of, localiser_steps_of

NOISE_SEED_SALT = 37
"""Mixed into the scenario's seed, so that the noise does not repeat the start poses' draw."""


@dataclass(frozen=True)
class Noise:
    odometry_per_metre: float = 0.0
    odometry_per_radian: float = 0.0
    localiser_sigma: float = 0.0
    localiser_heading: float = 0.0  # radians
    localiser_period: int = 0  # control periods between fixes; 0: no localiser
    localiser_delay: int = 0  # control periods from the pose a fix measures to its arrival
    command_delay: int = 0  # control periods from a command to the wheels
    cover_margin: float = 0.0  # the team's map asks (1 + this) Λ* of every cell

    @property
    def none(self) -> bool:
        """No noise at all: the belief is the truth (whatever the cover margin)."""
        return replace(self, cover_margin=0.0) == Noise()


def noise_of(scenario: Scenario) -> Noise:
    """The scenario's ``[noise]`` table, its times in whole control periods."""
    given = dict(scenario.noise)
    period, delay = localiser_steps_of(scenario)
    return Noise(
        odometry_per_metre=given.get("odometry_per_metre", 0.0),
        odometry_per_radian=given.get("odometry_per_radian", 0.0),
        localiser_sigma=given.get("localiser_sigma", 0.0),
        localiser_heading=math.radians(given.get("localiser_heading_deg", 0.0)),
        localiser_period=period,
        localiser_delay=delay,
        command_delay=round(given.get("command_latency", 0.0) / scenario.dt),
        cover_margin=cover_margin_of(scenario),
    )


def in_own_frame(before: np.ndarray, after: np.ndarray) -> np.ndarray:
    """(N, 3): each robot's motion from ``before`` to ``after`` (N, 3) in its frame at ``before``: forward,
    sideways, turn."""
    dx, dy = after[:, 0] - before[:, 0], after[:, 1] - before[:, 1]
    cos, sin = np.cos(before[:, 2]), np.sin(before[:, 2])
    turn = np.angle(np.exp(1j * (after[:, 2] - before[:, 2])))
    return np.stack([cos * dx + sin * dy, -sin * dx + cos * dy, turn], axis=1)


def moved_by(poses: np.ndarray, motion: np.ndarray) -> np.ndarray:
    """``poses`` (N, 3) moved by ``motion`` (N, 3) given in each one's own frame (:func:`in_own_frame`)."""
    cos, sin = np.cos(poses[:, 2]), np.sin(poses[:, 2])
    x = poses[:, 0] + cos * motion[:, 0] - sin * motion[:, 1]
    y = poses[:, 1] + sin * motion[:, 0] + cos * motion[:, 1]
    return np.stack([x, y, np.angle(np.exp(1j * (poses[:, 2] + motion[:, 2])))], axis=1)


class Sensors:
    """What every robot's sensors give, period by period, from the true poses the world gives: wheel odometry
    (its motion in the robot's frame, with drift) and the localiser's fixes, each arriving
    ``localiser_delay`` periods after the pose it measured (see the module). The in-process belief
    (:class:`Belief`) and the simulator's ROS 2 bases (simulator/) read the same draws."""

    def __init__(self, noise: Noise, truth: np.ndarray, seed: int) -> None:
        self.noise = noise
        self.rng = np.random.default_rng([seed, NOISE_SEED_SALT])
        self.truth = truth.copy()
        self.step = 0
        self.measured: deque[tuple[int, int, np.ndarray]] = deque()  # (arrival, measured at, fix) in flight

    def update(self, truth: np.ndarray) -> tuple[np.ndarray, list[tuple[int, np.ndarray]]]:
        """The world's true poses after one more period: the odometry's motion (N, 3) over it, and the
        fixes that arrive now, each with the step whose pose it measured."""
        motion = in_own_frame(self.truth, truth)
        self.truth, self.step = truth.copy(), self.step + 1
        odometry = motion + self._drift(motion)
        noise = self.noise
        if noise.localiser_period and self.step % noise.localiser_period == 0:
            fix = truth + self.rng.normal(0.0, 1.0, truth.shape) * [
                noise.localiser_sigma, noise.localiser_sigma, noise.localiser_heading
            ]  # fmt: skip
            fix[:, 2] = np.angle(np.exp(1j * fix[:, 2]))
            self.measured.append((self.step + noise.localiser_delay, self.step, fix))
        arrived = []
        while self.measured and self.measured[0][0] <= self.step:
            _, measured_at, fix = self.measured.popleft()
            arrived.append((measured_at, fix))
        return odometry, arrived

    def _drift(self, motion: np.ndarray) -> np.ndarray:
        travelled = np.abs(motion[:, :2]).sum(axis=1, keepdims=True)
        sigma = np.hstack([
            np.sqrt(travelled) * self.noise.odometry_per_metre * np.ones((len(motion), 2)),
            np.sqrt(np.abs(motion[:, 2:3])) * self.noise.odometry_per_radian,
        ])  # fmt: skip
        return self.rng.normal(0.0, 1.0, motion.shape) * sigma


def predicted_variance(variance: np.ndarray, motion: np.ndarray, noise: Noise) -> np.ndarray:
    """(N, 2) the belief's variance, in position (each axis) and heading, after the odometry's ``motion`` (N, 3,
    each robot's own frame): the drift's own, as :class:`Sensors` draws it (σ² per unit travelled and per radian
    turned), and the heading's doubt carried along the way travelled (a heading off by ε puts a step of d off
    by ε d sideways)."""
    travelled = np.abs(motion[:, :2]).sum(axis=1)
    turned = np.abs(motion[:, 2])
    position = variance[:, 0] + noise.odometry_per_metre**2 * travelled + travelled**2 * variance[:, 1]
    heading = variance[:, 1] + noise.odometry_per_radian**2 * turned
    return np.stack([position, heading], axis=1)


def fix_gains(variance: np.ndarray, noise: Noise) -> np.ndarray:
    """(N, 2) the Kalman gains K = P / (P + σ²) of a localiser's fix in position and heading, P the belief's
    variance (:func:`predicted_variance`), σ the fix's: 1 where the fix is exact, 0 where the belief is."""
    return gains_against(variance, np.array([noise.localiser_sigma**2, noise.localiser_heading**2]))


def gains_against(variance: np.ndarray, measured: np.ndarray) -> np.ndarray:
    """:func:`fix_gains` for a fix whose variance (position per axis, heading) is ``measured``: a real
    localiser's covariance, which a ROS 2 driver reads from each fix."""
    total = variance + measured
    exact = total <= 0.0
    return np.where(exact, 1.0, variance / np.where(exact, 1.0, total))


def fused(belief: np.ndarray, fix: np.ndarray, gains: np.ndarray) -> np.ndarray:
    """``belief`` (N, 3) moved toward ``fix`` (N, 3) by ``gains`` (N, 2: position, heading), the heading's
    difference taken the short way round."""
    turn = np.angle(np.exp(1j * (fix[:, 2] - belief[:, 2])))
    x = belief[:, 0] + gains[:, 0] * (fix[:, 0] - belief[:, 0])
    y = belief[:, 1] + gains[:, 0] * (fix[:, 1] - belief[:, 1])
    return np.stack([x, y, np.angle(np.exp(1j * (belief[:, 2] + gains[:, 1] * turn)))], axis=1)


class Belief:
    """Every robot's believed pose, kept from the true poses the world gives each period (see the module)."""

    def __init__(self, noise: Noise, truth: np.ndarray, seed: int) -> None:
        self.noise = noise
        self.sensors = Sensors(noise, truth, seed)
        self.poses = truth.copy()  # the start pose is known
        self.variance = np.zeros((len(truth), 2))  # exactly
        keep = noise.localiser_delay + 1
        self.odometry: deque[np.ndarray] = deque(maxlen=keep)  # the last periods' odometry motions

    def update(self, truth: np.ndarray) -> np.ndarray:
        """The world's true poses after one more period; the beliefs (N, 3) then."""
        if self.noise.none:
            self.poses = truth.copy()
            return self.poses
        odometry, arrived = self.sensors.update(truth)
        self.odometry.append(odometry)
        self.poses = moved_by(self.poses, odometry)
        self.variance = predicted_variance(self.variance, odometry, self.noise)
        for _, fix in arrived:
            gains = fix_gains(self.variance, self.noise)
            self.poses = fused(self.poses, self._replayed(fix), gains)
            self.variance = (1.0 - gains) * self.variance
        return self.poses

    def _replayed(self, fix: np.ndarray) -> np.ndarray:
        """A fix of the pose ``localiser_delay`` periods ago, the odometry since replayed on it."""
        poses = np.array(fix)
        for odometry in list(self.odometry)[len(self.odometry) - self.noise.localiser_delay :]:
            poses = moved_by(poses, odometry)
        return poses


class CommandDelay:
    """Commands (N, 2) reach the wheels ``delay`` periods after they are given; before the first arrives,
    the wheels get zero."""

    def __init__(self, delay: int, agents: int) -> None:
        self.waiting: deque[np.ndarray] = deque([np.zeros((agents, 2))] * delay)

    def __call__(self, commands: np.ndarray) -> np.ndarray:
        self.waiting.append(np.array(commands))
        return self.waiting.popleft()
