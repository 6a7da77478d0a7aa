# Copyright 2026 football_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Track a thrown ball from noisy position fixes and predict where and when it lands.

Filter: an unscented Kalman filter (scaled sigma points x +/- alpha sqrt(n) L_i, alpha =
``spread``, beta = 2). Why not an EKF: the motion model is the package's compiled full model
(:mod:`.motion`, on :func:`football_ros.physics.dynamics.loads`), which changes as the physics
evolves and has no Jacobian; sigma points need none (2n + 1 = 29 compiled propagations per
frame), and the same points carry the uncertainty through the nonlinear landing (the z = 0
crossing) to give the landing point's covariance and the landing time's variance. The
measurement (a position) is linear, so the update is the exact Kalman update (Joseph form).
What limits the prediction is what the fixes cannot yet tell (spin, axis, coefficients): the
Bayesian Cramer-Rao bound of the landing point (:mod:`.bound`, bench/prediction_bound.py)
says how close any predictor can get; bench/prediction_benchmark.py measures this filter
against it and against simpler predictors (figures: bench/RESULTS.md).

State x (``N_X`` = 14), in ``field``: position r [m], velocity v [m/s], spin axis s (unit),
modified angular momentum h = H / I_t [rad/s] (so h1 = h.s is the spin momentum), a drag scale
``kd`` (multiplies C_D0 and C_D2) and a lift scale ``kl`` (multiplies C_Lalpha). The motion is
the full model's (the spin angle is not needed). Why carry the attitude: the side force is the
lift of the yaw of repose, which lags the equilibrium of the linear theory and swings with the
slow (precession) mode; a quasi-steady axis (the equilibrium sideslip) misses the landing by
decimetres even with the true state and spin.

The axis and spin are not observable from positions at first. A throw starts with the axis
along the velocity (``axis_sigma``), no mean transverse rate (``rate_sigma``, about its
physical spread at track start: ``min_points`` fixes after the release the overturning moment
has built a few tenths of a rad/s) and |h1| = the ball preset's nominal spin (``spin_sigma``,
by default the spread of real throws, :data:`SPIN_SPREAD`), with h = h1 s + h_perp correlated
with s (the momentum turns with the axis). Without that correlation the prior describes balls
nutating at h1 delta, and the filter locks on a wrong spin and lift scale with an
overconfident covariance (see test_a_lob_with_more_lift_is_not_locked_on_a_wrong_spin).
The hand is unknown, so filters run for both hands (right- and left-handed spin), each hand's
|spin| prior a Gaussian sum: ``spin_components`` slices of the spread of real spins, one filter
each (a single wide Gaussian lets a low-spin kick's spin estimate cross zero before the fixes
tell, overconfident). The predictions mix them by likelihood; a filter is dropped once the best
outweighs it by ``hand_odds`` (the lateral drift tells the hands apart within a few tenths of a
second).

Track management: a throw starts when ``min_points`` unassociated fixes within ``init_window``
of the newest fit a ballistic arc (known gravity) to within the noise and move faster than
``min_speed`` but not than ``max_speed``; the arc is found by consensus (the arcs through the
new fix and each buffered one, at most one fix per stamp), so clutter, a second ball or wild
stamps among the buffered fixes neither hide it nor empty the buffer. Fixes whose innovation is
beyond the Mahalanobis gate are rejected (and, after ``reinit_after`` in a row that form a new
arc, start a new throw, :attr:`FlightTracker.restart_reason` saying why; a rejected fix without
a position, a camera's pixels, then answers 'candidate', asking for its position: a camera's
range, :mod:`.camera_fusion`); a late fix (older than the newest) rolls the filter back to the
checkpoint before it and re-applies the later fixes; a fix from the future or non-finite is
refused, and one older than ``max_lag`` too, unless such old fixes form an arc of their own: the
clock of the fixes jumped back (a restart), the time base is reset and the throw starts
(:meth:`FlightTracker.reset_time_base`). The throw ends (landed) when the estimate reaches the
ground, or will before the fix after next is due (the last frames before the ground may be
lost). Several balls: :mod:`.multi`. Times [s] are on the observations' clock.

Wind: a known steady wind (``wind``) enters the model; with ``wind_sigma`` > 0 the state has two
more entries (``N_X_WIND``), the unknown horizontal wind, flown point by point.

Predictions once one hand is left (``refine_iterations`` > 0): a batch MAP fit of every fix of
the throw under the same prior (:mod:`.refine`), warm-started at each prediction. The filter's
process noise, which keeps it honest and lets it follow a ball the model misses, also makes it
forget; the fit keeps all the fixes, and so comes closer to the information bound. Where
either finds the ball gyroscopically unstable (a kick that may tumble), the multi-start fit
(``unstable_fits``) keeps its own covariance if its objective passes a chi-square check, the
filters keeping the chance that it sits in a wrong basin; else (or without ``unstable_fits``)
the prediction keeps the fit's mean with the filters' tumbling covariance, widened by how far
the two lie apart (docs/physics.md, "Low spin and tumbling").
"""

from __future__ import annotations

import bisect
import collections
from dataclasses import dataclass, field, replace
import math
from types import SimpleNamespace

import numpy as np

from .measurement import (
    Measurement, position_fix, PositionFix, unscented_update, with_timing
)
from .motion import (
    fly_state,
    fly_to_planes,
    N_X,
    N_X_WIND,
    NO_PLANE,
    path_of,
    propagate_points,
    X_H,
    X_KD,
    X_KL,
    X_R,
    X_S,
    X_V,
    X_W,
)
from .refine import Prior, refine, Refined
from .sensor import check_numbers
from .unscented import moments, sigma_points
from ..physics import dynamics as dyn
from ..physics.aero import AeroModel, resolve
from ..physics.modes import gyroscopic_stability
from ..physics.presets import get_preset
from ..physics.release import LIMITS, RPM

CHI2_3_9999 = 21.11  # chi-square 3 dof, 99.99 %
CHI2_Z95 = 1.645
"""Standard normal 95 % point: the chi-square check of an unstable kick's fit
(:func:`_wrong_basin`)."""
WRONG_BASIN = (0.05, 2.0)
"""An unstable kick's multi-start fit: the chance that it sits in a wrong basin although it passes
the chi-square check (one in twenty on the prediction benchmark's tumbling cases: its landing
off by 4-20 of its sigmas), and how
far such a basin's objective lies above a right one's [standard deviations of chi-square]
(:func:`_wrong_basin`)."""
MAX_BASINS = 3
"""Other basins of an unstable kick's fit kept beside it at most (:func:`_basins`)."""
TUMBLE_PHASES = (-0.5, 0.5)
"""The axis of a tumble start also tilted by these angles [rad] about the pitch axis (with
``basin_reach`` > 0, :meth:`FlightTracker._prior_starts`): where a tumble is in its turn at
the first fix is unknown."""
FOLLOW = (4, 8)
"""An unstable kick's fits followed from one prediction to the next (:meth:`FlightTracker._refit`):
at most this many Levenberg-Marquardt iterations for a fit whose last fit is at most this many
fixes older (a node predicting every few fixes); the fit goes on from where it stopped at the next
prediction."""
LADDER = (10, 2.0, 6)
"""An unstable kick's multi-start fit on a part of its fixes (:meth:`FlightTracker._spread_fits`):
the fewest fixes of the first quarter, the reach (x ``basin_reach``) and the most basins kept
from one part to the next."""
MAX_FIXES = 1000
"""Fixes of a throw kept for the batch fit (beyond, every other one is dropped: bounded cost)."""
LONGEST = 120.0
"""Flight [s] to which the sigma points still aloft at ``horizon`` are flown on (the most
``horizon`` accepts): only a point that cannot be flown, or stays up 2 min, leaves a plane
without a prediction (:meth:`FlightTracker._plane_moments`)."""
ARC_INFLATION = 4.0
"""Factor on the start arc's covariance for the filter's start (the arc ignores drag and lift)."""
PLANE_COLUMNS = (slice(0, 4), slice(4, 8), slice(8, 13))
"""Columns of :func:`.motion.fly_to_planes`'s rows: landing, height, wall (each ends in a flag)."""
CARRY_VARIANCE = {X_KD: 0.05**2, X_KL: 0.05**2, X_W: 1.0, X_W + 1: 1.0}
"""Variance added to a learned scale (and to a learned wind [m^2/s^2]) from one throw to the
next: gusts and a ball that gets wet or scuffed."""


HAND_FITS = ('never', 'pixels', 'always')
"""Choices of ``hand_fits`` (:class:`TrackerSettings`)."""
DECISIVE = math.log(100.0)
"""Log evidence by which one hand's fit beats the other's (odds 100:1) before the loser is fitted
again from the winner's state, its spin reversed: a verdict must not rest on a fit held in a
local minimum."""


# --- settings and results -----------------------------------------------------------------------
SPIN_SPREAD = {'american': 0.19, 'rugby': 0.5}
"""Default ``spin_sigma`` of a ball preset: the standard deviation of |spin| over the nominal,
from the spread of real throws taken as uniform: spirals 400-800 rpm around 600 (115 rpm),
screw kicks 60-600 rpm around 300 (156 rpm); 0.3 for another ball."""
SPIN_COMPONENTS = {'american': 2, 'rugby': 4}
"""Default ``spin_components`` of a ball preset (2 for another ball): slices of its spin spread,
one Gaussian each (bench/prediction_benchmark.py: the landing errors and NEES per count)."""


@dataclass(frozen=True)
class TrackerSettings:
    """
    Filter settings (SI).

    ``noise`` [m] 1-sigma per axis of the fixes; ``accel_noise`` [m/s^2/sqrt(Hz)] white model-error
    acceleration, plus ``tumble_noise`` x (1 - S_g) when the estimate is gyroscopically unstable
    (McCoy's S_g < 1: a low-spin kick whose axis motion the sigma points cannot follow);
    ``axis_noise`` [rad/sqrt(s)] and ``rate_noise`` [rad/s/sqrt(s)] on s and h; ``scale_rate``
    [1/sqrt(s)] random walk of kd and kl; priors ``axis_sigma`` [rad], ``rate_sigma`` [rad/s]
    (transverse), ``spin_sigma`` (fraction of the nominal spin; None = the ball's
    :data:`SPIN_SPREAD`), ``spin_components`` Gaussians of |spin| a hand (None = the ball's
    :data:`SPIN_COMPONENTS`), ``scale_sigma`` (of kd and kl, mean 1); ``spin_rpm`` nominal |spin|
    [rev/min] (None = the ball preset's); ``hand_odds`` likelihood ratio by which the best drops
    another filter (a hand, a spin component); ``gate`` squared Mahalanobis distance; ``max_lag``
    [s] oldest fix accepted behind the newest; ``max_future`` [s] newest fix ahead of ``now``;
    ``max_gap`` [s] silence that ends a track; ``min_points``, ``init_window`` [s], ``min_speed``
    and ``max_speed`` [m/s] (by default the fastest release, :data:`.release.LIMITS`; the
    arc's velocity is taken under a weak prior of that size, :meth:`FlightTracker._physical`)
    for a new throw (the window grows to ``min_points`` + 1 fix intervals of a slow
    camera, the interval measured from the fixes' stamps); ``stamp_jitter`` [s, 1 sigma] of the
    fixes' stamps, folded into each fix's noise along the velocity (the larger of it and the
    jitter measured from the stamps' spacing, :func:`measured_jitter`); ``spread`` the
    unscented transform's alpha (points at alpha sqrt(n)
    sigma); ``reinit_after`` rejected fixes in a row that may start a new throw; ``step`` [s]
    filter integration step, ``landing_step`` [s] for predictions; ``horizon`` [s] of the landing
    search; ``ground`` [m] height of the landing plane; ``ball`` preset; ``aero`` the full model's
    settings the filter assumes (None = the defaults); ``wind`` (x, y) [m/s] a known steady wind in
    ``field`` (an anemometer's); ``wind_sigma`` [m/s] > 0 adds two states, the unknown horizontal
    wind beyond ``wind`` (prior sigma per axis), with random walk ``wind_rate`` [m/s/sqrt(s)];
    ``gust_rate`` [m/s/sqrt(s)] > 0 runs each filter twice, in steady air (no wind states, or
    ``wind_rate`` with ``wind_sigma`` > 0) and in gusts (two wind states, prior sigma
    ``wind_sigma`` or ``gust_rate`` x 1 s, a random walk of this rate), mixed by likelihood (a
    multiple model; 0 = still air only): the gusty share is the predictions', widened by the
    gusts still to come; ``gust_prior`` (0-0.5) the odds of gusty air before the fixes tell,
    kept as a floor under each gusty twin's likelihood against its still-air twin (the air may
    turn gusty at any time).
    ``refine_iterations`` > 0: once one hand is left, the predictions come from a batch MAP fit
    of every fix of the throw (:mod:`.refine`, at most that many Levenberg-Marquardt steps a
    prediction, warm-started from the last); 0 = the filter's own estimate. ``hand_fits``: while
    both hands are alive, 'always' fits each hand and mixes the two by their evidence, 'pixels'
    (default) only once the throw has fixes that are not positions (a camera's pixels, whose
    depth axis may hide the drift that tells the hands apart all flight) or, with
    ``unstable_fits``, the kick is gyroscopically unstable (its wobble hides that drift),
    'never' (the filters' mixture until one hand is left). ``unstable_fits`` (off by default):
    the fit of an unstable kick (S_g < 1) takes ``tumble_rate_sigma`` [rad/s] as the prior of
    its transverse rate (a punt end over end, not a spiral's wobble) and starts from every
    filter of its hand, from its prior and from ``tumble_starts`` tumbles (rates up to
    ``tumble_rate_sigma``, end over end either way), the lowest objective kept: its likelihood
    has several optima (:meth:`FlightTracker._refit`). The prediction takes the fit's own
    covariance where the fit passes a chi-square check, the filters' mixture keeping the
    chance that it sits in a wrong basin, else the filters' tumbling covariance
    (:func:`_wrong_basin`); False: the filters' tumbling covariance always, and no multi-start.
    ``basin_reach`` (with ``unstable_fits``): the other basins the multi-start finds within this
    much -2 log evidence of the best fit's (13.8: a thousandth of its weight) are kept beside it
    and refitted as the fixes come, and the prediction mixes them all by their Laplace evidence
    (:func:`_basins`); to find them the starts are also fitted to the first quarter and half of
    the fixes and the tumble starts' axis tilted (:meth:`FlightTracker._spread_fits`). 0: one
    basin, the lowest objective alone.
    Off by default for its CPU: an unstable kick then costs many fits, the multi-start run
    inside a prediction (bench/RESULTS.md, "tracker CPU, unstable_fits off and on"; spirals
    and gusts untouched); on a day of kicks, on, where the CPU allows (tumbling kicks come far
    closer to the global bound, their covariance honest: "prediction bound, tumbling kicks,
    unstable_fits on, seeds 3..4" and its lead 0.5 s).

    The noise and prior defaults make the covariance honest (landing NEES 2 or below) on the
    prediction benchmark's still-air flights; the gusty twins (``gust_rate``, on by default)
    take in an unmodelled wind, which would make a still-air filter's covariance lie, at the
    cost of a wider covariance in still air and twice the filter's CPU (bench/RESULTS.md).
    """

    noise: float = 0.02
    accel_noise: float = 0.007
    tumble_noise: float = 1.0
    axis_noise: float = 0.001
    rate_noise: float = 0.01
    scale_rate: float = 0.003
    axis_sigma: float = 0.03
    rate_sigma: float = 0.3
    spin_sigma: float | None = None
    spin_components: int | None = None
    scale_sigma: float = 0.2
    spread: float = 0.5
    spin_rpm: float | None = None
    hand_odds: float = 1e6
    gate: float = CHI2_3_9999
    max_lag: float = 0.5
    max_future: float = 0.5
    max_gap: float = 0.5
    min_points: int = 5
    init_window: float = 0.25
    min_speed: float = 3.0
    max_speed: float = LIMITS['speed'][1]
    stamp_jitter: float = 0.0
    reinit_after: int = 6
    step: float = 0.005
    landing_step: float = 0.01
    horizon: float = 15.0
    ground: float = 0.0
    ball: str = 'american'
    aero: AeroModel | None = None
    wind: tuple = (0.0, 0.0)
    wind_sigma: float = 0.0
    wind_rate: float = 0.2
    gust_rate: float = 3.0
    gust_prior: float = 0.01
    refine_iterations: int = 25
    hand_fits: str = 'pixels'
    unstable_fits: bool = False
    tumble_rate_sigma: float = 15.0
    tumble_starts: int = 8
    basin_reach: float = 13.8

    LIMITS = {
        'noise': (1e-4, 10.0),
        'accel_noise': (0.0, 100.0),
        'tumble_noise': (0.0, 100.0),
        'axis_noise': (0.0, 10.0),
        'rate_noise': (0.0, 100.0),
        'scale_rate': (0.0, 10.0),
        'axis_sigma': (1e-4, 1.0),
        'rate_sigma': (1e-4, 100.0),
        'spin_sigma': (1e-3, 1.0),
        'spin_components': (1, 8),
        'scale_sigma': (1e-3, 2.0),
        'spread': (0.1, 1.0),
        'hand_odds': (1.0, 1e300),
        'gate': (1.0, 1e4),
        'max_lag': (0.0, 10.0),
        'max_future': (0.0, 100.0),
        'max_gap': (0.01, 100.0),
        'min_points': (3, 100),
        'init_window': (0.01, 10.0),
        'min_speed': (0.0, 100.0),
        'max_speed': (1.0, 300.0),
        'stamp_jitter': (0.0, 0.1),
        'reinit_after': (1, 1000),
        'step': (1e-4, 0.02),
        'landing_step': (1e-4, 0.05),
        'horizon': (0.1, LONGEST),
        'ground': (-100.0, 100.0),
        'wind_sigma': (0.0, 30.0),
        'wind_rate': (0.0, 10.0),
        'gust_rate': (0.0, 20.0),
        'gust_prior': (1e-6, 0.5),
        'refine_iterations': (0, 100),
        'tumble_rate_sigma': (1e-4, 100.0),
        'tumble_starts': (0, 32),
        'basin_reach': (0.0, 100.0),
    }

    def __post_init__(self) -> None:
        if self.spin_sigma is None:  # the ball's own (a bad ball is refused below)
            spread = SPIN_SPREAD.get(self.ball, 0.3) if isinstance(self.ball, str) else 0.3
            object.__setattr__(self, 'spin_sigma', spread)
        if self.spin_components is None:
            count = SPIN_COMPONENTS.get(self.ball, 2) if isinstance(self.ball, str) else 2
            object.__setattr__(self, 'spin_components', count)
        check_numbers('tracker', self, self.LIMITS)  # the counts' int limits: ints
        if self.min_speed >= self.max_speed:
            raise ValueError(
                f"tracker 'min_speed' ({self.min_speed:g}) must be below 'max_speed' "
                f'({self.max_speed:g})'
            )
        if self.spin_rpm is not None and (
            isinstance(self.spin_rpm, bool)
            or not isinstance(self.spin_rpm, (int, float))
            or not 10.0 <= abs(self.spin_rpm) <= 3000.0
        ):
            raise ValueError(
                f"tracker 'spin_rpm' must be None or |.| in [10, 3000], got {self.spin_rpm!r}"
            )
        get_preset(self.ball)  # raises ValueError for an unknown ball
        if not isinstance(self.unstable_fits, bool):
            raise ValueError(f"tracker 'unstable_fits' must be a bool, got {self.unstable_fits!r}")
        if self.hand_fits not in HAND_FITS:
            raise ValueError(
                f"tracker 'hand_fits' must be one of {HAND_FITS}, got {self.hand_fits!r}"
            )
        try:
            wind = tuple(float(w) for w in self.wind)
        except (TypeError, ValueError):
            wind = ()
        if len(wind) != 2 or not all(math.isfinite(w) and abs(w) <= 50.0 for w in wind):
            raise ValueError(
                f"tracker 'wind' must be 2 numbers (x, y) in [-50, 50] m/s, got {self.wind!r}"
            )
        object.__setattr__(self, 'wind', wind)


@dataclass(frozen=True)
class LandingPrediction:
    """
    Predicted landing on z = ground (or crossing of a catch height, or of a vertical plane).

    ``time`` [s] on the observations' clock and its variance [s^2], ``position`` (3,) [m] and
    ``covariance`` [m^2]: (2, 2) of x, y on a horizontal plane (z = the plane's), (3, 3) of x,
    y, z on a vertical one (:func:`vertical_plane`); made from the estimate at ``made_at`` [s].
    """

    time: float
    time_variance: float
    position: np.ndarray
    covariance: np.ndarray
    made_at: float


def vertical_plane(x: float, y: float, heading_deg: float) -> np.ndarray:
    """
    Return the vertical plane through (``x``, ``y``) [m] crossed heading ``heading_deg``.

    A receiver's plane in ``field``: the ball crosses it moving along the horizontal direction
    ``heading_deg`` [deg] from +x towards +y (0: a pass along +x). Returns (px, py, nx, ny), the
    form :meth:`FlightTracker.predict_planes` takes. Raises ValueError naming the bad argument.
    """
    check_numbers(
        'vertical plane',
        SimpleNamespace(x=x, y=y, heading_deg=heading_deg),
        {'x': (-1e4, 1e4), 'y': (-1e4, 1e4), 'heading_deg': (-360.0, 360.0)},
    )
    a = math.radians(heading_deg)
    return np.array([float(x), float(y), math.cos(a), math.sin(a)])


def _plane_or_none(plane) -> np.ndarray:
    """Return ``plane`` as (px, py, nx, ny) if finite with a unit normal, else :data:`NO_PLANE`."""
    try:
        wall = np.asarray(plane if plane is not None else NO_PLANE, dtype=float).reshape(4)
    except (TypeError, ValueError):
        return NO_PLANE
    if not (np.all(np.isfinite(wall)) and abs(math.hypot(wall[2], wall[3]) - 1.0) < 1e-6):
        return NO_PLANE
    return wall


@dataclass(frozen=True)
class UpdateResult:
    """
    What :meth:`FlightTracker.update` did.

    ``status`` is one of 'accepted', 'started' (a new throw), 'candidate' (kept for a possible
    new throw), 'outlier', 'late', 'future', 'duplicate', 'invalid'; ``reason`` says why for a
    refusal; ``landed`` is True on the fix that ended the throw.
    """

    status: str
    reason: str = ''
    landed: bool = False

    @property
    def used(self) -> bool:
        return self.status in ('accepted', 'started')


@dataclass
class _Hypothesis:
    x: np.ndarray
    P: np.ndarray
    loglik: float = 0.0
    hand: float = 1.0  # sign of the spin it started with
    gusty: bool = False  # its wind a random walk of gust_rate (else wind_rate)
    component: int = 0  # its spin prior's slice (and hand): a still-air filter and its gusty twin

    def copy(self) -> '_Hypothesis':
        return replace(self, x=self.x.copy(), P=self.P.copy())


@dataclass
class _Entry:
    stamp: float
    meas: Measurement  # as given (its stamp's jitter is folded in when it is filtered)
    hyps: list  # hypotheses after this fix (accepted or not)
    t: float  # time of their state
    rejected_in_row: int


@dataclass
class _Track:
    hyps: list
    t: float
    history: collections.deque = field(default_factory=lambda: collections.deque(maxlen=90))
    landed: bool = False
    rejected_in_row: int = 0
    fixes: dict = field(default_factory=dict)  # stamp -> Measurement the filter took (jitter
    # folded in), the arc's too
    prior: tuple = ()  # (index, mean, sigma) of the scales (and wind) at the start
    fits: dict = field(default_factory=dict)  # hand -> (key, Refined or None), its last fit
    release_speed: float = 0.0  # [m/s] at the arc's first fix: where S_g is the lowest
    release_at: int = 0  # fixes when release_speed was last estimated
    pixels: bool = False  # a fix other than a 3D position (a camera's pixels) was taken
    spread_at: dict = field(default_factory=dict)  # hand -> fixes at its last multi-start fit
    basins: dict = field(default_factory=dict)  # hand -> [Refined]: its fit's other basins
    # within ``basin_reach`` (unstable_fits)

    def keep(self, t: float, meas: Measurement) -> None:
        """Record a fix the filter took; past MAX_FIXES every other older one is dropped."""
        self.fixes[t] = meas
        self.pixels = self.pixels or not isinstance(meas, PositionFix)
        if len(self.fixes) > MAX_FIXES:
            stamps = sorted(self.fixes)
            for stamp in stamps[1:-1:2]:
                del self.fixes[stamp]

    @property
    def best(self) -> _Hypothesis:
        return max(self.hyps, key=lambda h: h.loglik)


# --- the tracker --------------------------------------------------------------------------------
class FlightTracker:
    """
    Unscented Kalman filter on the full model, with track start/end and landing prediction.

    Feed fixes with :meth:`update` (any order); read :attr:`estimate`, :meth:`predict_landing`
    and :meth:`predict_path`. Every output is finite (or None).
    """

    def __init__(self, settings: TrackerSettings | None = None) -> None:
        self.settings = s = settings or TrackerSettings()
        preset = get_preset(s.ball)
        ball, aero = resolve(preset, 'full', s.aero)
        self.ball = ball
        self.params = dyn.make_params(ball, 'linear', aero)
        self.params[dyn.P_WIND] += s.wind[0]  # a known wind (an anemometer), field frame
        self.params[dyn.P_WIND + 1] += s.wind[1]
        spin = abs(preset.spin_rpm if s.spin_rpm is None else s.spin_rpm) * RPM
        self.nominal_h1 = ball.inertia_ratio * spin  # [rad/s]
        self.track: _Track | None = None
        self.throws = 0
        depth = max(64, 8 * s.min_points)  # candidate fixes kept (clutter, wild stamps too)
        self._candidates: collections.deque = collections.deque(maxlen=depth)
        self._old: collections.deque = collections.deque(maxlen=depth)
        self._newest = -math.inf
        self.frame_stamps: collections.deque = collections.deque(maxlen=32)
        """Stamps [s] of the latest fixes seen (any track's): the camera's measured rate."""
        self.time_resets = 0
        self.counts: collections.Counter = collections.Counter()
        self.no_prediction = 'no throw'
        """Why the last :meth:`predict_planes` (or :meth:`predict_landing`) gave no landing
        ('' if it gave one)."""
        self.restart_reason = ''
        """Why the current throw was started again in flight ('' if it was not): its filters
        rejected ``reinit_after`` fixes or more in a row and these formed an arc."""
        self.learned: dict | None = None
        """Prior of the next throw's drag and lift scales (and wind): {state index: (mean,
        variance)} from a throw of the same ball in the same air (:meth:`learn_from`)."""

    def learn_from(self, other: 'FlightTracker') -> bool:
        """
        Carry ``other``'s current scales (and wind) to this tracker's next throw as its prior.

        Their variances grow by :data:`CARRY_VARIANCE` (the air and the ball change a little
        between throws). False if ``other`` has no estimate.
        """
        est = other.estimate
        if est is None:
            return False
        _, x, P = est
        self.learned = {i: (float(x[i]), float(P[i, i])) for i in CARRY_VARIANCE if i < x.size}
        return True

    # --- public API -----------------------------------------------------------------------
    def update(
        self, stamp: float, position, now: float | None = None, covariance=None
    ) -> UpdateResult:
        """
        Process one position fix.

        Capture time ``stamp`` [s], ``position`` (3,) [m] in ``field``; ``now`` [s]
        (optional, same clock) refuses fixes from the future; ``covariance`` (3, 3) [m^2] in
        ``field`` of this fix (None: ``noise``^2 I). A bad one is refused ('invalid', the
        reason naming it).
        """
        try:
            meas = position_fix(position, covariance, self.settings.noise)
        except (TypeError, ValueError) as exc:
            field_name = 'covariance' if covariance is not None else 'position'
            result = UpdateResult('invalid', f'{field_name}: {exc}')
            self.counts[result.status] += 1
            return result
        return self.observe(stamp, meas, now)

    def observe(self, stamp: float, meas: Measurement, now: float | None = None) -> UpdateResult:
        """
        Process one fix of any measurement model (:mod:`.measurement`) taken at ``stamp`` [s].

        Only a fix that gives a position (:meth:`Measurement.position_guess`) can start a throw;
        any can update one.
        """
        result = self._update(stamp, meas, now)
        self.counts[result.status] += 1
        return result

    @property
    def estimate(self) -> tuple[float, np.ndarray, np.ndarray] | None:
        """
        Return (time [s], state (N_X,), covariance (N_X, N_X)) of the current throw.

        The estimate of the current throw's most likely hand, or None.
        """
        if self.track is None:
            return None
        best = self.track.best
        return self.track.t, best.x.copy(), best.P.copy()

    @property
    def landed(self) -> bool:
        return self.track is not None and self.track.landed

    @property
    def hand(self) -> float | None:
        """Return the sign of the current throw's spin once one hand is left (else None)."""
        if self.track is None:
            return None
        hands = {hyp.hand for hyp in self.track.hyps}
        return hands.pop() if len(hands) == 1 else None

    def predict_landing(self) -> LandingPrediction | None:
        """
        Predict the landing of the current throw from the sigma points of the estimate.

        None without a throw or if it does not land within ``horizon``. While both hands
        are alive the prediction is their mixture, weighted by likelihood; once one is left,
        with ``refine_iterations`` > 0, the batch fit's (:mod:`.refine`). Model error adds
        q T^3 / 3 to the x and y variances (q: accel_noise^2, and the tumbling term while the
        estimate is gyroscopically unstable).
        """
        return self.predict_planes(-math.inf)[0]

    def predict_crossing(self, height: float) -> LandingPrediction | None:
        """
        Predict where and when the current throw next comes down through z = ``height`` [m].

        Like :meth:`predict_landing` (position z = ``height``, covariance of x and y); None
        without a throw, for a non-finite height, or if some sigma point does not come down
        through that height before the ground (a ball that will not rise to it).
        """
        return self.predict_planes(height)[1]

    def predict_through(self, plane: np.ndarray) -> LandingPrediction | None:
        """
        Predict where and when the current throw goes through the vertical ``plane``.

        ``plane`` from :func:`vertical_plane`; position (x, y, z) [m] on it, covariance (3, 3)
        of x, y, z; None without a throw or if some sigma point lands first.
        """
        return self.predict_planes(-math.inf, plane)[2]

    def predict_planes(
        self, height: float, plane: np.ndarray | None = None
    ) -> tuple[LandingPrediction | None, LandingPrediction | None, LandingPrediction | None]:
        """
        Return the landing and the crossings of ``height`` and of ``plane``, from one flight.

        Each sigma point is flown once to the ground, its crossings of z = ``height`` [m] and of
        ``plane`` (:func:`vertical_plane`, None: none) noted on the way: the catches cost
        nothing beyond the landing. A ``height`` that is not a number in [ground, ground +
        1000 m] gives no crossing; so does a plane the ball is already past, or that some sigma
        point does not reach before the ground. The vertical plane's covariance is that of x,
        y, z, the model error added within the plane.
        """
        s = self.settings
        try:
            h = float(height)
        except (TypeError, ValueError):
            h = math.nan
        if not (math.isfinite(h) and s.ground <= h <= s.ground + 1000.0):
            h = -math.inf
        wall = _plane_or_none(plane)
        tr = self.track
        if tr is None:
            self.no_prediction = 'no throw'
            return None, None, None
        fits = self._fits()
        gusty = self._gust_share(tr, fits)
        if fits is None:  # the filters, mixed by likelihood
            planes, model = self._mixture(tr, h, wall), tr.best.x
        else:  # the batch fit of every fix (one a hand while both are alive), mixed
            planes = _mix_planes([(w, self._plane_moments(f.x, f.P, h, wall)) for w, f in fits])
            top = max(fits, key=lambda wf: wf[0])[1]
            # whichever is less stable sets the tumbling allowance (the filter's only where it
            # knows its spin: a single camera's leaves it unknown, its mean meaningless)
            judged = [top.x] + ([tr.best.x] if _spin_known(tr.best) else [])
            model = min(judged, key=self._stability)
            if self._stability(model) < 1.0:  # a kick that may tumble: the fit's mean
                wrong = _wrong_basin(fits) if self._tumbling(tr) else None
                planes = [
                    None if f is None or m is None
                    # a multi-start fit that passes the chi-square check: its own moments
                    # (with ``basin_reach``, the mixture of the basins within reach by their
                    # evidence), the filters' mixture keeping the chance that none is right
                    else _mix([(1.0 - wrong, f), (wrong, m)]) if wrong is not None
                    # else the filters' covariance (it carries the tumbling all flight),
                    # widened by how far the fit lies from them
                    else (f[0], m[1] + np.outer(f[0] - m[0], f[0] - m[0]))
                    for f, m in zip(planes, self._mixture(tr, h, wall))
                ]
                if wrong is not None:  # the fit flies the full model, attitude and all, and
                    # its fixes in steady air: no tumbling allowance, and the gusty filters'
                    # share (filters that cannot follow the tumble, whose misfit gusts take in)
                    # only in the wrong basin's; the gusts to come are still added
                    model = None
            if gusty > 1e-3 and model is not None:  # the fit stands for still air; the gusty
                # filters keep their share
                # (when a gusty filter cannot be flown to a plane, a sigma point of an absurd
                # hypothesis outside the horizon, the fit stands for all: the gusts to come
                # are still added below)
                planes = [
                    f if f is None or g is None else _mix([(1.0 - gusty, f), (gusty, g)])
                    for f, g in zip(planes, self._mixture(tr, h, wall, gusty_only=True))
                ]
        q = s.accel_noise**2 if model is None else self._accel_variance(model)
        gust = self._gust_variance(tr)
        if gust is not None:  # the gusts to come, for the gusty filters' share
            gust = gusty * gust
        landing = self._prediction(planes[0], q, (0.0, 0.0, 1.0), s.ground, gust)
        self.no_prediction = '' if landing is not None else (
            f'a sigma point of a hypothesis with weight cannot be flown or stays aloft beyond '
            f'{LONGEST:g} s' if planes[0] is None else 'the landing moments are not finite')
        return (
            landing,
            self._prediction(planes[1], q, (0.0, 0.0, 1.0), h, gust),
            self._prediction(planes[2], q, (wall[2], wall[3], 0.0), gust=gust),
        )

    def _gust_variance(self, tr: _Track) -> np.ndarray | None:
        """
        Return the x, y variance rate [m^2/s] of the gusts still to come, or None in steady air.

        In gusty air the wind is a random walk of ``gust_rate`` q from now: a change dw at time
        tau before the landing (time T) moves it by about J dw ((T - tau) / T)^2 (the drift
        grows with the square of the time it acts; J = d landing / d wind of the likeliest
        gusty filter's mean, flown), so the landing's variance grows by q J J' T / 5
        (:meth:`predict_planes` weighs it by the gusty filters' share).
        """
        gusty = [h for h in tr.hyps if h.gusty]
        if not gusty:
            return None
        pts = np.repeat(max(gusty, key=lambda h: h.loglik).x[None, :], 3, axis=0)
        pts[1, X_W] += 1.0
        pts[2, X_W + 1] += 1.0
        s = self.settings
        flown = fly_to_planes(pts, self.params, s.landing_step, -math.inf, s.ground, s.horizon,
                              NO_PLANE)
        if not np.all(flown[:, 3] == 1.0):
            return None
        J = (flown[1:, 1:3] - flown[0, 1:3]).T  # columns: per m/s of wind x, y
        return s.gust_rate**2 * (J @ J.T) / 5.0

    @staticmethod
    def _gusty_weight(tr: _Track) -> float:
        """Return the gusty filters' share of the likelihood (0 without them)."""
        if not any(h.gusty for h in tr.hyps):
            return 0.0
        lls = np.array([h.loglik for h in tr.hyps])
        w = np.exp(lls - lls.max())
        return float(sum(wk for wk, h in zip(w, tr.hyps) if h.gusty) / w.sum())

    def _gust_share(self, tr: _Track, fits: list | None) -> float:
        """
        Return the gusty air's share of the predictions: the filters', or the fit's verdict.

        The filters' (:meth:`_gusty_weight`), but where the throw has a camera's pixels and
        every steady-air fit that counts (``fits``, weight 1 % or more) passes the chi-square
        check (:func:`_passes`), at most ``gust_prior``: the fixes show no gust, and the
        filters' odds are no evidence of one. One camera's still-air filters, linearised along
        a ray whose range they know to metres, lose to their gusty twins, whose two more
        states take in that misfit: on the one-camera rig in still air the twins held over
        half the likelihood in 5 of 20 flights, and the predictions were then the filters'
        mixture, metres off along the ray, for a fit that explained the fixes. So too for a
        kick :meth:`_tumbling` treats as unstable (:meth:`_fit_judges_gusts`).
        """
        gusty = self._gusty_weight(tr)
        if fits is not None and self._fit_judges_gusts(tr) and all(
                _passes(f) for w, f in fits if w >= 0.01):
            return min(gusty, self.settings.gust_prior)
        return gusty

    def _fit_judges_gusts(self, tr: _Track) -> bool:
        """
        Whether the filters' odds of gusty air are no evidence, the fit's chi-square judging.

        A camera's pixels (:meth:`_gust_share`), or a kick :meth:`_tumbling` treats as unstable:
        the still-air filters cannot follow a tumble and their gusty twins take in the misfit.
        On an end-over-end punt in still air (prediction_benchmark's draw 3, flight 14; 0.5 s
        lead) the twins held 99.9 % of the likelihood, so no fit was made and the prediction
        was the filters' mixture, 27 cm off, for a fit that passed its chi-square and landed
        2 cm from the truth.
        """
        return tr.pixels or self._tumbling(tr)

    def _mixture(self, tr: _Track, height: float, wall: np.ndarray,
                 gusty_only: bool = False) -> list:
        """
        Return the filters' moments on each plane, mixed by likelihood (:data:`PLANE_COLUMNS`).

        [(mean, cov) or None where a point of a filter that counts missed the plane]; of the
        gusty filters alone with ``gusty_only``.
        """
        hyps = [hyp for hyp in tr.hyps if hyp.gusty or not gusty_only]
        if not hyps:
            return [None for _ in PLANE_COLUMNS]
        lls = np.array([hyp.loglik for hyp in hyps])
        weights = np.exp(lls - lls.max())
        weights /= weights.sum()
        return _mix_planes([
            (w, self._plane_moments(hyp.x, hyp.P, height, wall))
            for hyp, w in zip(hyps, weights) if w >= 1e-6 or len(hyps) == 1
        ])

    def _plane_moments(self, x, P, height: float, wall: np.ndarray) -> list:
        """
        Fly the sigma points of (``x``, ``P``) to the ground, noting the planes on the way.

        [(mean, cov) of (time, x, y[, z]) or None where a point missed it] for the landing,
        the height and the wall (:data:`PLANE_COLUMNS`). Points still aloft at ``horizon`` are
        flown on to :data:`LONGEST`: a component is one hypothesis of the mixture, and the
        mixture's covariance is honest only with every component's moments in it. Dropping
        the odd one (and renormalising) would make it silently narrower by the share of a
        hypothesis the fixes have not ruled out (a gusty filter held 42 % of a mono throw's
        weight when one of its points stayed up past 15 s); letting the fit stand for it, the
        same; and voiding the whole prediction for it left throws with seconds of fixes and
        a landed fit without any. Flown on, its far point widens the covariance, as it should.
        """
        s = self.settings
        pts, wm, wc = sigma_points(x, P, s.spread)
        flown = fly_to_planes(pts, self.params, s.landing_step, height, s.ground, s.horizon, wall)
        aloft = flown[:, 3] != 1.0
        if np.any(aloft) and s.horizon < LONGEST:  # flown on: the honest moments (module doc)
            flown[aloft] = fly_to_planes(pts[aloft], self.params, s.landing_step, height,
                                         s.ground, LONGEST, wall)
        out = []
        for cols in PLANE_COLUMNS:
            found = flown[:, cols]
            flown_all = np.all(found[:, -1] == 1.0) and np.all(np.isfinite(found))
            out.append(moments(found[:, :-1], wm, wc) if flown_all else None)
        return out

    def _fit(self) -> Refined | None:
        """
        Return the batch MAP fit (:mod:`.refine`) of the throw's one hand left, or None.

        None with ``refine_iterations`` 0, while both hands are alive, while the gusty filters
        hold more than half the likelihood (the fit flies a steady wind) unless, with a
        camera's pixels, the fit passes its chi-square check (:meth:`_gust_share`), or when it
        fails.
        The prior is the filter's at the first fix, its spin the hand's whole spread (one
        Gaussian: a fit from the filter's estimate needs no slices). Cached per newest fix;
        warm-started from the last fit of the throw, else from the filter's estimate flown back
        to the first fix.
        """
        s, tr, hand = self.settings, self.track, self.hand
        if s.refine_iterations == 0 or tr is None or hand is None or self._gusty(tr):
            return None
        fit = self._hand_fit(tr, hand)
        return fit if fit is None or self._steady(tr, [fit]) else None

    def _gusty(self, tr: _Track) -> bool:
        """
        Whether the gusty filters' share rules the batch fit out before it is made.

        Over half the likelihood, unless :meth:`_fit_judges_gusts`: then the fit is made and
        judged by its chi-square (:meth:`_steady`, :meth:`_gust_share`).
        """
        return self._gusty_weight(tr) > 0.5 and not self._fit_judges_gusts(tr)

    def _steady(self, tr: _Track, fits: list) -> bool:
        """Whether the steady-air ``fits`` may stand for ``tr`` (:meth:`_gust_share` <= 0.5)."""
        return self._gusty_weight(tr) <= 0.5 or all(_passes(f) for f in fits)

    def _fits(self) -> list[tuple[float, Refined]] | None:
        """
        Return the batch fits the predictions come from, with their weights, or None.

        Once one hand is left, its fit (:meth:`_fit`). While both are alive and ``hand_fits``
        asks for it (:class:`TrackerSettings`): a fit for each hand, weighted by its Laplace
        evidence exp(-cost / 2) |posterior covariance|^(1/2) (equal odds a priori; the priors
        differ in the sign of the spin alone). None: the filters' mixture (a fit failed, or
        gusty air rules them out: :meth:`_fit`).
        """
        s, tr = self.settings, self.track
        if self.hand is not None:
            fit = self._fit()
            return None if fit is None else _by_evidence([fit] + tr.basins.get(self.hand, []))
        if s.refine_iterations == 0 or tr is None or self._gusty(tr) or not (
            s.hand_fits == 'always' or s.hand_fits == 'pixels' and (
                tr.pixels or s.unstable_fits and self._stability(tr.best.x) < 1.0)
        ):
            return None
        fits = [self._hand_fit(tr, hand) for hand in (1.0, -1.0)]
        if any(f is None or not math.isfinite(f.logdet) for f in fits):
            return None
        evidence = np.array([_evidence(f) for f in fits])
        if abs(evidence[0] - evidence[1]) > DECISIVE:  # a verdict: the loser from the winner too
            lose = int(np.argmin(evidence))
            hand, win = (1.0, -1.0)[lose], fits[1 - lose]
            retry = self._fit_from(tr, hand, [_reversed(win.x0)])
            if retry is not None and math.isfinite(retry.logdet) and retry.cost < fits[lose].cost:
                fits[lose] = retry
                tr.fits[hand] = (tr.fits[hand][0], retry)
        weighted = _by_evidence(fits + [b for h in (1.0, -1.0) for b in tr.basins.get(h, [])])
        return weighted if self._steady(tr, [f for w, f in weighted if w >= 0.01]) else None

    def _hand_fit(self, tr: _Track, hand: float) -> Refined | None:
        """Return the fit of ``tr`` for ``hand`` (:meth:`_refit`), cached per newest fix."""
        key = (tr.t, len(tr.fixes))
        cached = tr.fits.get(hand)
        if cached is None or cached[0] != key:
            tr.fits[hand] = (key, self._refit(tr, hand))
        return tr.fits[hand][1]

    def _refit(self, tr: _Track, hand: float) -> Refined | None:
        """
        Fit ``tr``'s fixes for ``hand`` (:meth:`_fit`).

        From its last fit for that hand if it has one, else from that hand's likeliest filter.
        A fit that is not sound (its iterations ran out, or its spin momentum h.s has the other
        hand's sign: the other hand's minimum, held by the prior alone) is tried again from that
        hand's filter and from the other hand's fit with its spin reversed. With
        ``unstable_fits``, a kick the filters find gyroscopically unstable has a likelihood with
        several optima (the spin, the hand and a tumble trade off against the attitude), so at
        its first fit and whenever its fixes have doubled since, its fit also starts from each
        of the hand's filters and from its prior (:meth:`_prior_starts`, :meth:`_spread_fits`).
        The lowest objective is kept; the other basins those starts found within
        ``basin_reach`` of its evidence are kept beside it in ``tr.basins``, each refitted from
        its own last fit at every refit until it falls out of reach or into another's basin.
        Such a kick's fits are followed at a bounded cost (:data:`FOLLOW`), and one that is not
        sound is kept (its spin, near 0, takes either sign; the multi-starts cover the other
        starts) rather than refitted from two cold starts at nearly every prediction.
        """
        times = np.array(sorted(tr.fixes))
        if times[-1] != tr.t:
            return None
        last = tr.fits.get(hand)
        tumbling = self._tumbling(tr)
        follow = None  # iterations of a fit followed from its last (None: refine_iterations)
        if tumbling and last is not None and times.size - last[0][1] <= FOLLOW[1]:
            follow = FOLLOW[0]
        fit = None
        if last is not None and last[1] is not None:
            fit = self._fit_from(tr, hand, [last[1].x0], follow)
        if fit is None or not (_sound(fit, hand) or tumbling):
            starts = [self._filter_start(tr, hand, times)]
            other = tr.fits.get(-hand)
            if other is not None and other[1] is not None:
                starts.append(_reversed(other[1].x0))
            fit = _least(fit, self._fit_from(tr, hand, [x0 for x0 in starts if x0 is not None]))
        others = [self._fit_from(tr, hand, [b.x0], follow) for b in tr.basins.get(hand, [])]
        if tumbling and times.size >= 2 * tr.spread_at.get(hand, 0):
            tr.spread_at[hand] = times.size
            back = [fly_state(h.x, [times[0] - tr.t], self.params, self.settings.step)[0]
                    for h in _hand_filters(tr, hand)]
            if back:
                found = self._spread_fits(tr, hand, back + self._prior_starts(back[0], hand))
                others += found
        for other in others:
            fit = _least(fit, other)
        tr.basins[hand] = _basins(fit, others, self.settings.basin_reach)
        return fit

    def _tumbling(self, tr: _Track) -> bool:
        """Whether ``unstable_fits`` treats ``tr`` as an unstable kick (its best filter's S_g)."""
        return self.settings.unstable_fits and self._stability(tr.best.x) < 1.0

    def _filter_start(self, tr: _Track, hand: float, times: np.ndarray) -> np.ndarray | None:
        """
        Return the likeliest filter that can be flown back to ``times[0]``, flown there.

        That hand's still-air filters (else any's), then the gusty ones, that hand's first,
        without their wind (the fit flies a steady wind): one camera's still-air filters can
        diverge along the ray while their twins take over (a mono flight's fit had no start
        and its prediction was the filters', 1.2 m off against the fit's 0.2 m). None if none.
        """
        n = N_X_WIND if self.settings.wind_sigma > 0.0 else N_X
        gusty = sorted((h for h in tr.hyps if h.gusty), key=lambda h: (h.hand != hand, -h.loglik))
        for hyp in _hand_filters(tr, hand) + gusty:
            x = fly_state(hyp.x[:n], [times[0] - tr.t], self.params, self.settings.step)[0]
            if np.all(np.isfinite(x)):
                return x
        return None

    def _fit_from(self, tr: _Track, hand: float, starts: list,
                  iterations: int | None = None) -> Refined | None:
        """
        Return the fit (:func:`.refine.refine`) of ``tr`` for ``hand`` of least objective.

        Over ``starts`` (states at the first fix), ``iterations`` each (None:
        ``refine_iterations``); the transverse rate's prior is ``tumble_rate_sigma`` for a
        kick :meth:`_tumbling` treats as unstable. None if none fits.
        """
        best = None
        for fit in self._fits_from(tr, hand, starts, iterations):
            best = _least(best, fit)
        return best

    def _fits_from(self, tr: _Track, hand: float, starts: list, iterations: int | None = None,
                   count: int | None = None, secant: bool = False) -> list[Refined]:
        """
        Return the fits of :meth:`_fit_from`, one a start that fits, in the starts' order.

        Of the first ``count`` fixes (None: all); ``secant``: :func:`.refine.refine`'s.
        """
        s = self.settings
        times = np.array(sorted(tr.fixes))[:count]
        prior = Prior((hand * self.nominal_h1, self.nominal_h1 * s.spin_sigma), s.axis_sigma,
                      s.tumble_rate_sigma if self._tumbling(tr) else s.rate_sigma, tr.prior)
        fixes = [tr.fixes[t] for t in times]
        out = []
        for x0 in starts:
            if np.all(np.isfinite(x0)):
                fit = refine(times, fixes, x0, prior, s.noise, self.params, s.step,
                             iterations or s.refine_iterations, secant)
                if fit is not None:
                    out.append(fit)
        return out

    def _spread_fits(self, tr: _Track, hand: float, starts: list) -> list[Refined]:
        """
        Return the fits of ``tr`` for ``hand`` from many ``starts``, lowest objective first.

        Each start takes ``refine_iterations`` steps; the lowest is polished with three times
        as many (cold starts take more steps than a warm one), and so are the other basins
        within ``basin_reach`` of its evidence (:func:`_basins`; 0: the lowest alone). With
        ``basin_reach`` > 0 the starts are also fitted to the first quarter of the fixes, then
        the basins kept (:data:`LADDER`) to the first half, and these join the starts: a
        tumbling flight's objective is rugged over seconds of fixes and smooth over a fraction
        of one, and the basins are followed as the fixes grow (as a tracker predicting at
        every fix does). The starts' fits carry their Jacobians by secant updates (one flight a
        step, :func:`.refine.refine`); the polish flies them.
        """
        reach = self.settings.basin_reach
        climbed = starts
        for part in (4, 2) if reach > 0.0 and len(tr.fixes) >= 4 * LADDER[0] else ():
            fits = self._fits_from(tr, hand, climbed, count=len(tr.fixes) // part, secant=True)
            if not fits:
                break
            top = min(fits, key=lambda f: f.cost)
            climbed = [f.x0 for f in [top] + _basins(top, fits, LADDER[1] * reach, LADDER[2])]
        fits = self._fits_from(tr, hand, starts + (climbed if climbed is not starts else []),
                               secant=True)
        if not fits:
            return []
        top = fits[0]
        for fit in fits[1:]:
            top = _least(top, fit)
        polish = [top] + _basins(top, fits, self.settings.basin_reach)
        out = [_least(f, self._fit_from(tr, hand, [f.x0], 3 * self.settings.refine_iterations))
               for f in polish]
        return sorted(out, key=lambda f: f.cost)

    def _prior_starts(self, x: np.ndarray, hand: float) -> list[np.ndarray]:
        """
        Return starts of a fit drawn from its prior, at the position and velocity of ``x``.

        The axis along the velocity (the prior's mean), spinning at each of ``hand``'s spin
        prior slices (:meth:`_spin_prior`) and at a tenth of the nominal; then at that slow
        spin, ``tumble_starts`` tumbles: the transverse momentum h - (h.s) s [rad/s] along
        s x z (end over end, either way), of sizes spread evenly up to ``tumble_rate_sigma``,
        each also with its axis tilted by :data:`TUMBLE_PHASES` (``basin_reach`` > 0).
        """
        s = self.settings
        axis = x[X_V:X_V + 3] / np.linalg.norm(x[X_V:X_V + 3])
        pitch = np.cross(axis, (0.0, 0.0, 1.0))
        if not np.all(np.isfinite(axis)) or np.linalg.norm(pitch) < 1e-6:
            return []
        pitch /= np.linalg.norm(pitch)
        spins = [h1 for sign, h1, _ in self._spin_prior() if sign == hand]
        h1 = hand * 0.1 * self.nominal_h1
        out = []
        for h in [hand * m for m in spins] + [h1]:
            y = x.copy()
            y[X_S:X_S + 3] = axis
            y[X_H:X_H + 3] = h * axis
            out.append(y)
        half = (s.tumble_starts + 1) // 2
        for i in range(s.tumble_starts):
            rate = s.tumble_rate_sigma * (i // 2 + 1) / half * (1.0 if i % 2 == 0 else -1.0)
            y = x.copy()
            y[X_H:X_H + 3] = h1 * axis + rate * pitch
            out.append(y)
            for phase in TUMBLE_PHASES if s.basin_reach > 0.0 else ():
                y = x.copy()
                tilted = math.cos(phase) * axis + math.sin(phase) * np.cross(pitch, axis)
                y[X_S:X_S + 3] = tilted
                y[X_H:X_H + 3] = h1 * tilted + rate * pitch
                out.append(y)
        return out

    def _prediction(self, moments_, q: float, normal, height: float = math.nan, gust=None):
        """
        Return the prediction on one plane of unit ``normal`` from its (mean, cov), or None.

        Horizontal planes (z = ``height``) carry (time, x, y) moments, vertical ones (time, x,
        y, z). The model error's variance q T^3 / 3 is added in the plane (``q``
        [m^2/s^4/Hz] from :meth:`_accel_variance`, T the time to the plane), and ``gust`` T to
        x, y (:meth:`_gust_variance`, None: none).
        """
        if moments_ is None:
            return None
        mean, cov = moments_
        t_land = float(mean[0])
        extra = q * max(t_land, 0.0) ** 3 / 3.0
        n = np.asarray(normal, dtype=float)
        project = np.eye(3) - np.outer(n, n)
        in_plane = extra * project
        if gust is not None:  # the gusts' drift, x y, within the plane
            drift = np.zeros((3, 3))
            drift[:2, :2] = gust * max(t_land, 0.0)
            in_plane += project @ drift @ project
        if mean.size == 3:  # a horizontal plane
            if not math.isfinite(height):
                return None
            position = np.array([mean[1], mean[2], height])
            cov_pos = cov[1:, 1:] + in_plane[:2, :2]
        else:
            position = mean[1:]
            cov_pos = cov[1:, 1:] + in_plane
        var_t = float(cov[0, 0])
        if not (
            np.all(np.isfinite(position)) and np.all(np.isfinite(cov_pos)) and math.isfinite(var_t)
        ):
            return None
        return LandingPrediction(self.track.t + t_land, var_t, position, cov_pos, self.track.t)

    def predict_path(self, sample_dt: float = 0.05) -> tuple[np.ndarray, np.ndarray] | None:
        """
        Remaining path of the mean estimate (the batch fit's where the predictions use one).

        Times (m,) [s] on the observations' clock and positions (m, 3) [m], every
        ``sample_dt`` [s] until the ground.
        """
        tr = self.track
        if tr is None or not (0.001 <= sample_dt <= 10.0):
            return None
        s = self.settings
        fits = self._fits()
        times, pos = path_of(
            tr.best.x if fits is None else max(fits, key=lambda wf: wf[0])[1].x, self.params,
            sample_dt, s.landing_step, s.ground, s.horizon
        )
        if not np.all(np.isfinite(pos)):
            return None
        return tr.t + times, pos

    # --- internals ------------------------------------------------------------------------
    def _update(self, stamp, meas, now) -> UpdateResult:
        s = self.settings
        try:
            t = float(stamp)
        except (TypeError, ValueError):
            return UpdateResult('invalid', 'stamp must be a number')
        if not isinstance(meas, Measurement):
            return UpdateResult('invalid', 'not a measurement')
        guess = meas.position_guess()
        if not math.isfinite(t):
            return UpdateResult('invalid', 'non-finite stamp')
        if (guess is not None and np.any(np.abs(guess) > 1e5)) or abs(t) > 1e12:
            return UpdateResult('invalid', 'position beyond 100 km or absurd stamp')
        if now is not None and math.isfinite(now) and t > now + s.max_future:
            return UpdateResult('future', f'stamp {t - now:.3f} s ahead of now')
        self.frame_stamps.append(t)
        if t < self._newest - s.max_lag:
            result = self._behind(t, meas)
            if result.used:
                self._newest = t
            return result
        tr = self.track
        if tr is None or tr.landed or abs(t - tr.t) > s.max_gap:
            # No live throw, or a fix far from it in time (the ball lost for a while, or a
            # wild stamp): it can only help start a new throw.
            result = self._candidate(t, meas)
        elif t < tr.t or (tr.history and t < tr.history[-1].stamp):
            result = self._late(tr, t, meas)
        elif tr.history and _same(tr.history[-1], t, meas):
            result = UpdateResult('duplicate', 'this fix was already processed')
        elif _offered(tr, t, meas, s.reinit_after):
            result = self._restart(tr, t, meas)
        else:
            result = self._filter(tr, t, meas, record=True)
        if result.used:  # only fixes the filter took move the "newest" (no wild stamp can)
            self._newest = max(self._newest, t)
        return result

    def _filter(self, tr: _Track, t: float, meas: Measurement, record: bool) -> UpdateResult:
        s = self.settings
        new_hyps, accepted, taken = [], False, meas
        best = tr.best
        jitter = self._jitter(tr, t, meas.source)
        for hyp in tr.hyps:
            x, P, ok = self._predict(hyp.x, hyp.P, t - tr.t, hyp.gusty)
            new = hyp.copy()
            if ok:
                try:
                    folded = with_timing(meas, x[:3], x[X_V:X_V + 3], jitter)
                except ValueError:  # a diverged filter's speed: no finite noise along it
                    folded = None
                up = None if folded is None else unscented_update(x, P, folded, s.spread)
                if up is not None:
                    # A filter that refuses a fix another takes is scored on it all the same
                    # (predicted, not updated): the fix counts against the model that missed.
                    new = replace(hyp, x=x, P=P, loglik=hyp.loglik - 0.5 * (up.d2 + up.logdet))
                if up is not None and up.d2 <= s.gate:
                    x = up.x
                    x[X_S:X_S + 3] /= np.linalg.norm(x[X_S:X_S + 3])
                    if np.all(np.isfinite(x)):
                        new = replace(new, x=x, P=up.P)
                        # the likeliest decides; a gusty filter also takes what still air
                        # cannot explain (a gust beyond the still-air filter's gate)
                        if hyp is best or (hyp.gusty and not best.gusty and not accepted):
                            accepted, taken = True, folded
            new_hyps.append(new)
        if accepted:
            tr.hyps, tr.t = new_hyps, t
            tr.keep(t, taken)
            tr.rejected_in_row = 0
            self._candidates.clear()
            self._prune(tr)
            self._release_speed(tr)
            result = UpdateResult('accepted')
        else:
            tr.rejected_in_row += 1
            result = UpdateResult('outlier', 'innovation beyond the Mahalanobis gate')
        if record:
            tr.history.append(
                _Entry(t, meas, [h.copy() for h in tr.hyps], tr.t, tr.rejected_in_row)
            )
        if not accepted:
            if record and tr.rejected_in_row >= s.reinit_after:
                if meas.position_guess() is None:  # pixels cannot start a throw: ask for a
                    # position of this fix (a camera's range), which may (:meth:`_update`)
                    return UpdateResult('candidate', f'{tr.rejected_in_row} fixes in a row '
                                        'beyond the gate: a position of this one may start '
                                        'the throw again')
                restart = self._restart(tr, t, meas)
                if restart.status == 'started':
                    return restart
            elif record and meas.position_guess() is not None:
                self._candidates.append((t, meas))
            return result
        if tr.best.x[2] <= s.ground or self._below_ground_soon(tr):
            tr.landed = True
            return UpdateResult(result.status, landed=True)
        return result

    def _restart(self, tr: _Track, t: float, meas: Measurement) -> UpdateResult:
        """
        Take a fix that ``tr`` rejected, ``reinit_after`` or more in a row, as a new throw's.

        Kept for a new arc (:meth:`_candidate`); when the rejected fixes form one, the throw
        starts again from it (its filters had lost the ball: an absurd start seen along a
        camera's ray rejected 27 fixes in a row and predicted nothing) and
        :attr:`restart_reason` says why.
        """
        rejected = tr.rejected_in_row
        result = self._candidate(t, meas)
        if result.status == 'started':
            self.restart_reason = (
                f'{rejected} fixes in a row beyond the gate of the throw started at '
                f'{min(tr.fixes):.3f} s: started again from their arc at {t:.3f} s'
            )
        return result

    def _prune(self, tr: _Track) -> None:
        """
        Drop the hypotheses (a hand, a spin component) that the best outweighs ``hand_odds``.

        A gusty filter is kept within ``gust_prior`` of its still-air twin's likelihood (air
        may turn gusty at any time: the odds of a switch, as in an interacting multiple
        model), so that still air early in a throw does not rule out a gust later.
        """
        still = {h.component: h.loglik for h in tr.hyps if not h.gusty}
        lift = math.log(self.settings.gust_prior) if self.settings.gust_prior > 0.0 else None
        for h in tr.hyps:
            if h.gusty and lift is not None and h.component in still:
                h.loglik = max(h.loglik, still[h.component] + lift)
        if len(tr.hyps) > 1:
            floor = tr.best.loglik - math.log(self.settings.hand_odds)
            tr.hyps = [h for h in tr.hyps if h.loglik >= floor]

    def _release_speed(self, tr: _Track) -> None:
        """
        Re-estimate ``tr.release_speed`` [m/s]: the likeliest filter flown back to the first fix.

        The arc's speed at the start is a guess from a few fixes: a single camera's range along
        its ray makes it tens of m/s off (measured: 41.8 m/s for a 16.7 m/s pass), and S_g,
        which falls with the square of the speed, judged there would call a spiral a tumbling
        kick all flight (the tumbling allowance, the filter's covariance for the fit's). Each
        time the throw's fixes have grown by a quarter (a few dozen flights back a throw). At
        most ``max_speed``: no throw is faster (a filter that diverged flew back at 116.7 m/s).
        """
        n = len(tr.fixes)
        if n < 1.25 * tr.release_at:
            return
        tr.release_at = n
        x = fly_state(tr.best.x, [min(tr.fixes) - tr.t], self.params, self.settings.step)[0]
        speed = float(np.linalg.norm(x[X_V:X_V + 3]))
        if math.isfinite(speed) and speed > 0.0:
            tr.release_speed = min(speed, self.settings.max_speed)

    def _below_ground_soon(self, tr: _Track) -> bool:
        """
        Tell whether the mean reaches the ground before the fix after next is due.

        Two fix intervals (the median of the recent ones; 10 ms to 0.1 s): the camera may lose
        the last frame before the ground (a dropout, or a frame captured just before the
        landing whose delivery never comes), and a throw whose end is never seen is never
        reported as landed.
        """
        x = tr.best.x
        if x[5] >= 0.0:
            return False
        stamps = sorted(e.stamp for e in list(tr.history)[-12:])
        gaps = np.diff(stamps)
        gaps = gaps[gaps > 0.0]
        ahead = min(max(2.0 * float(np.median(gaps)), 0.01), 0.1) if gaps.size else 0.01
        pt = x[None, :].copy()
        propagate_points(pt, ahead, self.params, self.settings.step)
        return bool(pt[0, 2] <= self.settings.ground)

    def _late(self, tr: _Track, t: float, meas: Measurement) -> UpdateResult:
        """Roll back to the checkpoint before ``t`` and re-apply the later fixes in order."""
        stamps = [e.stamp for e in tr.history]
        j = bisect.bisect_right(stamps, t)
        if j == 0:
            return UpdateResult('late', 'older than the kept history of the throw')
        if any(_same(e, t, meas) for e in list(tr.history)[max(0, j - 8):j]):
            return UpdateResult('duplicate', 'this fix was already processed')
        later = list(tr.history)[j:]
        base = tr.history[j - 1]
        for _ in range(len(later)):
            tr.history.pop()
        for stamp in [k for k in tr.fixes if k > base.stamp]:  # re-taken below if they pass
            del tr.fixes[stamp]
        tr.hyps, tr.t = [h.copy() for h in base.hyps], base.t
        tr.rejected_in_row, tr.landed = base.rejected_in_row, False
        result = self._filter(tr, t, meas, record=True)
        for e in later:
            if self.track is not tr or tr.landed:
                break
            self._filter(tr, e.stamp, e.meas, record=True)
        return result

    def _predict(self, x, P, dt, gusty: bool = False):
        s = self.settings
        if dt <= 0.0:
            return x.copy(), P.copy(), True
        pts, wm, wc = sigma_points(x, P, s.spread)
        propagate_points(pts, dt, self.params, s.step)
        if not np.all(np.isfinite(pts)):  # a point that cannot be flown (an absurd start)
            return x.copy(), P.copy(), False
        xm, Pm = moments(pts, wm, wc)
        q = self._accel_variance(x)
        for i in range(3):
            Pm[i, i] += q * dt**3 / 3.0
            Pm[i, 3 + i] += q * dt**2 / 2.0
            Pm[3 + i, i] += q * dt**2 / 2.0
            Pm[3 + i, 3 + i] += q * dt
            Pm[X_S + i, X_S + i] += s.axis_noise**2 * dt
            Pm[X_H + i, X_H + i] += s.rate_noise**2 * dt
        Pm[X_KD, X_KD] += s.scale_rate**2 * dt
        Pm[X_KL, X_KL] += s.scale_rate**2 * dt
        if xm.size == N_X_WIND:
            rate = s.gust_rate if gusty else s.wind_rate
            Pm[X_W, X_W] += rate**2 * dt
            Pm[X_W + 1, X_W + 1] += rate**2 * dt
        xm[X_S:X_S + 3] /= np.linalg.norm(xm[X_S:X_S + 3])
        ok = bool(np.all(np.isfinite(xm)) and np.all(np.isfinite(Pm)))
        return xm, 0.5 * (Pm + Pm.T), ok

    def gyroscopic_stability(self, x: np.ndarray, min_speed: float = 0.0) -> float:
        """
        Return McCoy's S_g of a filter state (air speed against the parameters' wind).

        At the larger of the state's air speed and ``min_speed`` [m/s] (S_g falls as the speed
        grows: the overturning moment goes with its square).
        """
        h1 = float(x[X_H:X_H + 3] @ x[X_S:X_S + 3])  # = (I_s / I_t) p
        air = x[X_V:X_V + 3] - self.params[dyn.P_WIND:dyn.P_WIND + 3]
        if x.size == N_X_WIND:
            air[:2] -= x[X_W:X_W + 2]
        speed = max(math.sqrt(float(air @ air)), min_speed)
        if speed == 0.0:
            return math.inf
        return gyroscopic_stability(self.ball, speed, h1 / self.ball.inertia_ratio)

    def _stability(self, x: np.ndarray) -> float:
        """
        Return S_g of a state of the current throw at its release speed (or faster).

        A ball that tumbled near the release, where it is fastest and so least stable, keeps a
        random attitude after its S_g has risen past 1 near the apex: the spin learnt so far,
        judged at the speed the throw started with.
        """
        tr = self.track
        return self.gyroscopic_stability(x, tr.release_speed if tr is not None else 0.0)

    def _accel_variance(self, x: np.ndarray) -> float:
        """
        Model-error acceleration PSD [m^2/s^4/Hz]: more while the ball can tumble (S_g < 1).

        From the estimate's own S_g (its spin as learnt so far) at the release speed
        (:meth:`_stability`): the sigma points of a tumbling ball spread less than its real
        axis motion does.
        """
        s = self.settings
        unstable = min(max(1.0 - self._stability(x), 0.0), 1.0)
        return s.accel_noise**2 + (s.tumble_noise * unstable) ** 2

    def _candidate(self, t: float, meas: Measurement) -> UpdateResult:
        """Keep the fix; start a throw when it and recent ones fit a ballistic arc."""
        if meas.position_guess() is None:
            return UpdateResult('candidate', 'a fix without a position cannot start a throw')
        self._candidates.append((t, meas))
        arc = self._find_arc(self._candidates, t, meas)
        if isinstance(arc, str):
            return UpdateResult('candidate', arc)
        times, fixes, x0, cov, used = arc
        self._candidates = collections.deque(
            (c for k, c in enumerate(self._candidates) if k not in used),
            maxlen=self._candidates.maxlen,
        )
        return self._start(times, fixes, x0, cov)

    def _behind(self, t: float, meas: Measurement) -> UpdateResult:
        """
        Handle a fix older than the newest by more than ``max_lag``: late or a clock restart.

        Kept apart; when such fixes (the newest among them this one) fit a ballistic arc of
        their own, the clock of the fixes jumped back (a simulator restarted under
        use_sim_time, a detector rebooted): the time base is reset and a throw starts.
        """
        if meas.position_guess() is None:
            return UpdateResult('late', f'stamp {self._newest - t:.3f} s behind the newest fix')
        self._old.append((t, meas))
        arc = self._find_arc(self._old, t, meas)
        if isinstance(arc, str):
            return UpdateResult('late', f'stamp {self._newest - t:.3f} s behind the newest fix')
        jump = self._newest - t
        self.reset_time_base()
        times, fixes, x0, cov, _ = arc
        self._start(times, fixes, x0, cov)
        return UpdateResult('started', f'the clock jumped back {jump:.3f} s: time base reset')

    def reset_time_base(self) -> None:
        """Forget the throw, the newest stamp and every buffered fix (a clock that restarted)."""
        self.track = None
        self._newest = -math.inf
        self._candidates.clear()
        self._old.clear()
        self.time_resets += 1

    def start_window(self) -> float:
        """
        Return the window [s] in which ``min_points`` fixes must fit an arc to start a throw.

        ``init_window``, or ``min_points`` + 1 frame intervals where the camera is slower (the
        median spacing of the distinct :attr:`frame_stamps`, every fix's, so that a few stray
        detections alone do not look like a slow camera; at most 2 s).
        """
        s = self.settings
        gaps = np.diff(np.unique(np.asarray(self.frame_stamps, dtype=float)))
        if gaps.size == 0:
            return s.init_window
        return max(s.init_window, min((s.min_points + 1) * float(np.median(gaps)), 2.0))

    def jitter(self, stamps, min_gaps: int = 8) -> float:
        """
        Return the jitter [s] folded into the fixes: told or measured, the larger.

        Measured (:func:`measured_jitter`) from ``stamps`` [s] of one ball's fixes.
        """
        return max(self.settings.stamp_jitter, measured_jitter(stamps, min_gaps))

    def _jitter(self, tr: _Track, t: float, source=None) -> float:
        """Return :meth:`jitter` of the fixes of ``source`` the throw took lately and ``t``."""
        mine = [k for k, m in tr.fixes.items() if m.source == source]
        return self.jitter(mine[-40:] + [t])

    def _jitter_of(self, times, fixes, min_gaps: int) -> float:
        """Return :meth:`jitter` of fixes at ``times`` [s]: each source's, the largest."""
        by_source = collections.defaultdict(list)
        for tk, fix in zip(times, fixes):
            by_source[fix.source].append(tk)
        return max(
            [self.jitter(stamps, min_gaps) for stamps in by_source.values()]
            or [self.settings.stamp_jitter]
        )

    def _find_arc(self, buffer, t: float, meas: Measurement):
        """
        Find a ballistic arc through the fix (``t``, ``meas``) among the ``buffer``'s fixes.

        Fixes within :meth:`start_window` of ``t``; consensus (RANSAC over the pairs with the
        new fix, at most one fix per stamp) so that clutter, a second ball or wild stamps
        among them do not hide it; then a least-squares fit of the inliers to within each
        fix's noise (its covariance's largest sigma, and the stamps' jitter times the speed).
        Returns (times, fixes, x0, cov, buffer indices used) or the reason (str) there is none.
        """
        s = self.settings
        window = self.start_window()
        idx = [k for k, c in enumerate(buffer) if abs(c[0] - t) <= window]
        if len(idx) < s.min_points:
            return (
                f'waiting for enough fixes to start a throw ({len(idx)} of {s.min_points} '
                f'within {window:.2f} s)'
            )
        times = np.array([buffer[k][0] for k in idx])
        fixes = [buffer[k][1] for k in idx]
        zs = np.array([f.position_guess() for f in fixes])
        covs = np.array([f.R for f in fixes])
        sig2 = np.linalg.eigvalsh(covs)[:, -1]
        jit2 = s.stamp_jitter**2
        z = meas.position_guess()
        g = np.array([0.0, 0.0, self.params[dyn.P_GRAVITY]])
        best = None
        for j in range(len(idx)):
            dt = times[j] - t
            if abs(dt) < 1e-3:
                continue
            v = (zs[j] - z) / dt + 0.5 * g * dt  # velocity at t of the arc through both
            tau = (times - t)[:, None]
            err = np.linalg.norm(z + v * tau - 0.5 * g * tau**2 - zs, axis=1)
            loose = 8.0 * np.sqrt(sig2 + jit2 * float(v @ v)) + 0.05
            inl = _one_per_stamp(times, err / loose, 1.0)
            if best is None or inl.size > best.size:
                best = inl
        if best is None or best.size < s.min_points:
            return 'the recent fixes do not fit a ballistic arc yet'
        jit2 = self._jitter_of(times[best], [fixes[k] for k in best], 4) ** 2  # this ball's
        order = best[np.argsort(times[best], kind='stable')]
        keep = list(order)
        for _ in range(3):  # drop the worst fix at most a few times
            fit = self._ballistic_fit(times[keep], zs[keep], covs[keep], jit2)
            if fit is None:
                break
            x0, cov, resid, sigma = fit
            bad = resid / (4.0 + 0.01 / sigma)  # within 4 sigma + 1 cm: <= 1
            worst = int(np.argmax(bad))
            if bad[worst] <= 1.0:
                if np.linalg.norm(x0[3:6]) < s.min_speed:
                    return 'the fixes do not move like a throw'
                start = self._physical(x0, ARC_INFLATION * cov)  # the filter's start
                if isinstance(start, str):
                    return start
                x0, cov = start[0], start[1] / ARC_INFLATION
                return times[keep], [fixes[k] for k in keep], x0, cov, {idx[k] for k in keep}
            if len(keep) - 1 < s.min_points:
                break
            del keep[worst]
        return 'the recent fixes do not fit a ballistic arc yet'

    def _physical(self, x0: np.ndarray, cov: np.ndarray):
        """
        Return an arc's (x0, cov) under the physical prior of a throw's velocity, or why not.

        ``x0`` (6,) position [m] and velocity [m/s] in ``field`` at the arc's last fix, ``cov``
        (6, 6) the filter's start covariance of it (:data:`ARC_INFLATION`); the reason (str)
        where the arc is refused. An arc faster than ``max_speed`` (a physical limit of
        releases, :data:`football_ros.physics.release.LIMITS`) is clipped: taken under the
        prior of each velocity component N(0, (``max_speed`` / 2)^2), updated by the
        pseudo-fix v = 0 of that noise (Kalman, so the position along the ray moves with the
        speed). A start seen along a camera's ray, whose range from the apparent size leaves
        the speed tens of m/s uncertain, got through at 111 and 147 m/s, metres off along the
        ray; the filters' axis and spin, guessed from that velocity, were then unknown all
        flight. An arc still faster is no throw. Slower arcs are left alone: applied to every
        arc, the prior drew a triangulated stereo start (metres of noise per fix) to a few m/s,
        and the axis guessed along that velocity, and the spin with it, were so uncertain
        that a filter's sigma points overflowed.
        """
        s = self.settings
        if float(np.linalg.norm(x0[3:6])) <= s.max_speed:
            return x0, cov
        prior = (0.5 * s.max_speed) ** 2 * np.eye(3)
        gain = np.linalg.solve(cov[3:6, 3:6] + prior, cov[3:6, :]).T  # (6, 3)
        x1 = x0 - gain @ x0[3:6]
        cov1 = cov - gain @ cov[3:6, :]
        speed = float(np.linalg.norm(x1[3:6]))
        if not (np.all(np.isfinite(x1)) and np.all(np.isfinite(cov1))):
            return 'the fixes give no finite arc'
        if speed > s.max_speed:
            return (
                f'the fixes move at {speed:.1f} m/s, faster than a throw (max_speed '
                f'{s.max_speed:g} m/s)'
            )
        return x1, 0.5 * (cov1 + cov1.T)

    def _ballistic_fit(self, times, zs, covs, jit2: float):
        """
        r(t) = r1 + v1 (t - t1) - g/2 (t - t1)^2 z_hat, generalised least squares (t1 = last).

        Fix k weighted by the inverse of ``covs``[k] (3, 3) [m^2] + ``jit2`` v v' (the stamps'
        jitter [s^2], v the velocity of an unweighted first fit at the fix). Returns (x0, cov,
        each fix's Mahalanobis residual, its largest sigma [m]) or None.
        """
        tau = times - times[-1]
        if tau[0] > -1e-3:
            return None
        g = np.array([0.0, 0.0, self.params[dyn.P_GRAVITY]])
        A = np.column_stack([np.ones_like(tau), tau])
        target = zs + 0.5 * np.outer(tau**2, g)
        coef, *_ = np.linalg.lstsq(A, target, rcond=None)
        vel = coef[1][None, :] - np.outer(tau, g)
        C = covs + jit2 * np.einsum('ki,kj->kij', vel, vel)
        W = np.linalg.inv(C)
        blocks = np.concatenate([np.repeat(np.eye(3)[None], tau.size, 0),
                                 tau[:, None, None] * np.eye(3)], axis=2)  # (k, 3, 6)
        info = np.einsum('kai,kab,kbj->ij', blocks, W, blocks)
        try:
            cov = np.linalg.inv(info)
        except np.linalg.LinAlgError:
            return None
        x0 = cov @ np.einsum('kai,kab,kb->i', blocks, W, target)
        err = target - np.einsum('kai,i->ka', blocks, x0)
        resid = np.sqrt(np.einsum('ka,kab,kb->k', err, W, err))
        return x0, 0.5 * (cov + cov.T), resid, np.sqrt(np.linalg.eigvalsh(C)[:, -1])

    def _spin_prior(self) -> list[tuple[float, float, float]]:
        """
        Return the prior's components (hand, |h1| mean, |h1| sigma) [rad/s], both hands.

        The spread of real spins is taken as uniform (nominal x (1 +/- sqrt(3) ``spin_sigma``),
        at most 0 to twice the nominal): ``spin_components`` equal slices of it, each a
        Gaussian of its slice's mean and of sigma ``spin_sigma`` / ``spin_components`` (one
        slice: the nominal and ``spin_sigma``), since one wide Gaussian fits a low-spin kick
        badly: its spin estimate can cross zero before the fixes tell.
        """
        s = self.settings
        k = s.spin_components
        half = min(math.sqrt(3.0) * s.spin_sigma, 1.0)
        return [
            (hand, self.nominal_h1 * (1.0 + half * ((2 * i + 1) / k - 1.0)),
             self.nominal_h1 * s.spin_sigma / k)
            for hand in (1.0, -1.0)
            for i in range(k)
        ]

    def _start(self, times, fixes, x0, cov6) -> UpdateResult:
        """Start a throw from its arc: ``times`` (k,), ``fixes`` (k); x0, cov6 at the end."""
        s = self.settings
        t, t_span = times[-1], times[-1] - times[0]
        v = x0[3:6]
        # The axis of a spiral leaves the hand along the velocity and stays nearly fixed in
        # space at first: take the velocity at the first fix of the arc.
        v_first = v + np.array([0.0, 0.0, self.params[dyn.P_GRAVITY] * t_span])
        axis = v_first / np.linalg.norm(v_first)
        perp = np.eye(3) - np.outer(axis, axis)
        n_x = N_X_WIND if s.wind_sigma > 0.0 else N_X  # the still-air filters'
        P = np.zeros((n_x, n_x))
        P[:6, :6] = ARC_INFLATION * cov6
        speed = float(np.linalg.norm(v))
        for i in range(3):
            P[3 + i, 3 + i] += (0.01 * speed) ** 2
            P[i, i] += 1e-4
        # The axis is guessed along the arc's velocity, so it shares that velocity's error: a
        # noisy view (a mono camera's depth) leaves the direction itself uncertain.
        J = perp / float(np.linalg.norm(v_first))
        P[X_S:X_S + 3, :6] = J @ P[3:6, :6]
        P[:6, X_S:X_S + 3] = P[X_S:X_S + 3, :6].T
        P[X_S:X_S + 3, X_S:X_S + 3] = (
            s.axis_sigma**2 * perp + J @ P[3:6, 3:6] @ J.T + 1e-8 * np.eye(3)
        )
        P[X_KD, X_KD] = P[X_KL, X_KL] = s.scale_sigma**2
        if n_x == N_X_WIND:  # unknown steady wind beyond the known ``wind``, mean 0
            P[X_W, X_W] = P[X_W + 1, X_W + 1] = s.wind_sigma**2
        mean = {X_KD: 1.0, X_KL: 1.0, X_W: 0.0, X_W + 1: 0.0}
        gust_var = {X_W: s.gust_rate**2 * 1.0, X_W + 1: s.gust_rate**2 * 1.0}  # [m^2/s^2]
        for i, (m, var) in (self.learned or {}).items():  # the last throw's, if carried
            if math.isfinite(m) and math.isfinite(var) and var > 0.0:
                mean[i] = m
                if i < n_x:
                    P[i, i] = min(P[i, i], var + CARRY_VARIANCE[i])
                else:  # a wind only the gusty twins carry
                    gust_var[i] = min(gust_var[i], var + CARRY_VARIANCE[i])
        hyps = []
        for k, (hand, h1, h1_sigma) in enumerate(self._spin_prior()):
            x = np.zeros(n_x)
            x[:6] = x0
            x[X_S:X_S + 3] = axis
            x[X_H:X_H + 3] = hand * h1 * axis
            for i, m in mean.items():
                if i < n_x:
                    x[i] = m
            Ph = P.copy()
            Ph[X_H:X_H + 3, X_H:X_H + 3] = (
                h1_sigma**2 * np.outer(axis, axis) + s.rate_sigma**2 * perp
            )
            # h = h1 s + h_perp: the spin momentum turns with the axis (dh = h1 ds), so an
            # axis off the guess carries h along. Without this coupling the prior describes
            # balls whose h stays put while the axis is off, i.e. with transverse rates
            # h1 delta ~ 2 rad/s, far beyond rate_sigma.
            c = hand * h1 * P[X_S:X_S + 3, X_S:X_S + 3]
            Ph[X_H:X_H + 3, X_S:X_S + 3] = c
            Ph[X_S:X_S + 3, X_H:X_H + 3] = c.T
            Ph[X_H:X_H + 3, :6] = hand * h1 * P[X_S:X_S + 3, :6]
            Ph[:6, X_H:X_H + 3] = Ph[X_H:X_H + 3, :6].T
            Ph[X_H:X_H + 3, X_H:X_H + 3] += hand * h1 * c
            if s.gust_rate <= 0.0:
                hyps.append(_Hypothesis(x, Ph, 0.0, hand, component=k))
                continue
            hyps.append(_Hypothesis(x, Ph, math.log1p(-s.gust_prior), hand, component=k))
            # its twin in gusty air, with the wind's two states (in still air: mean 0, or
            # the last throw's, sigma the wind a gust of gust_rate brings in a second)
            xg, Pg = np.zeros(N_X_WIND), np.zeros((N_X_WIND, N_X_WIND))
            xg[:n_x], Pg[:n_x, :n_x] = x, Ph
            if n_x == N_X:
                for i in (X_W, X_W + 1):
                    xg[i] = mean[i]
                    Pg[i, i] = gust_var[i]
            hyps.append(_Hypothesis(xg, Pg, math.log(s.gust_prior), hand, True, k))
        self.restart_reason = ''
        self.track = _Track(hyps, float(t),
                            release_speed=min(float(np.linalg.norm(v_first)), s.max_speed))
        self.track.prior = tuple(
            (i, float(x[i]), math.sqrt(P[i, i])) for i in (X_KD, X_KL, X_W, X_W + 1) if i < n_x
        )
        jitter = self._jitter_of(times, fixes, 4)
        g = np.array([0.0, 0.0, self.params[dyn.P_GRAVITY]])
        for tk, fix in zip(times, fixes):  # the arc's velocity at each fix for its jitter
            v_k = v - g * (tk - t)
            self.track.keep(float(tk), with_timing(fix, fix.position_guess(), v_k, jitter))
        self.track.history.append(
            _Entry(float(t), fixes[-1], [h.copy() for h in hyps], float(t), 0)
        )
        self.throws += 1
        return UpdateResult('started')


def warm_up(settings: TrackerSettings | None = None):
    """
    Load (or compile) every kernel the tracker runs; return a CompileStep.

    A throw seen by a scratch tracker of ``settings``: the filter, the predictions on all
    planes, the path, the batch fit's flights and a late fix's roll-back (a state with the
    wind's two entries is the same array type: no other version).
    """
    import time

    from ..physics.precompile import CompileStep
    from . import motion, refine as batch_fit

    def counts():
        stats = [d.stats for module in (motion, batch_fit) for d in vars(module).values()
                 if hasattr(d, 'stats')]
        return (sum(sum(st.cache_hits.values()) for st in stats),
                sum(sum(st.cache_misses.values()) for st in stats))

    start, (hits, misses) = time.perf_counter(), counts()
    s = settings or TrackerSettings()
    scratch = FlightTracker(s)
    for k in range(12):
        t = k / 60.0
        scratch.update(t, (20.0 * t, 0.0, 1.8 + 12.0 * t - 4.905 * t * t))
    scratch.predict_planes(1.2, vertical_plane(10.0, 0.0, 0.0))
    scratch.predict_path(0.05)
    _, x, _ = scratch.estimate
    fly_state(x, [-0.01], scratch.params, s.step)  # the batch fit's kernels
    batch_fit.warm_up(x)
    scratch.update(0.5 / 60.0, (0.2, 0.0, 1.9))  # a late fix: the roll-back path
    new_hits, new_misses = counts()
    return CompileStep('tracker kernels (filter, predictions, batch fit)',
                       time.perf_counter() - start, new_hits - hits, new_misses - misses)


def _sound(fit: Refined, hand: float) -> bool:
    """Whether ``fit`` converged with a spin momentum h.s [rad/s] of ``hand``'s sign."""
    return fit.converged and hand * float(fit.x0[X_H:X_H + 3] @ fit.x0[X_S:X_S + 3]) > 0.0


def _spin_known(hyp: _Hypothesis) -> bool:
    """
    Whether a filter knows its spin momentum h.s [rad/s] to within its mean (1 sigma).

    Its S_g, judged at the mean, means nothing otherwise: seen by one camera, whose range
    along the ray leaves the start's axis (and so h) uncertain, a spiral's filters carried h
    with sigmas of 40-110 rad/s against a nominal 38, their means near 0 (S_g 0.1).
    """
    axis = hyp.x[X_S:X_S + 3]
    spin = float(hyp.x[X_H:X_H + 3] @ axis)
    return float(axis @ hyp.P[X_H:X_H + 3, X_H:X_H + 3] @ axis) < spin**2


def _offered(tr: _Track, t: float, meas: Measurement, after: int) -> bool:
    """
    Whether ``meas`` is a position offered for the pixels ``tr`` has just rejected at ``t``.

    Rejected ``after`` or more in a row (:meth:`FlightTracker._filter` asked for it: the same
    detection as a camera's range fix, which only a new throw may take).
    """
    if tr.rejected_in_row < after or not tr.history or meas.position_guess() is None:
        return False
    last = tr.history[-1]
    return abs(last.stamp - t) < 1e-9 and last.meas.position_guess() is None


def _hand_filters(tr: _Track, hand: float) -> list:
    """Return ``hand``'s still-air filters (else every still-air one), likeliest first."""
    still = [h for h in tr.hyps if not h.gusty]  # the fit flies a steady wind
    return sorted([h for h in still if h.hand == hand] or still, key=lambda h: -h.loglik)


def _wrong_basin(fits: list) -> float | None:
    """
    Return the chance that the fits of an unstable kick sit in a wrong basin, or None.

    None (a wrong basin) when a fit of weight 1 % or more fails the chi-square check, its
    objective above the 95 % point of chi-square with ``dof`` degrees of freedom
    (Wilson-Hilferty; one right fit in twenty fails and takes the filters' wider covariance:
    width, not a lie). Else the posterior of two hypotheses on the worst z = (cost - dof) /
    sqrt(2 dof): right (z ~ N(0, 1)) or wrong (z ~ N(shift, 1)), prior odds and shift
    :data:`WRONG_BASIN`: a wrong basin that fits the fixes almost as well (another tumble or
    spin) is told only by a slightly higher objective.
    """
    odds, shift = WRONG_BASIN
    worst = -math.inf
    for w, fit in fits:
        if w < 0.01:
            continue
        if not _passes(fit):
            return None
        worst = max(worst, (fit.cost - fit.dof) / math.sqrt(2.0 * fit.dof))
    ratio = odds / (1.0 - odds) * math.exp(shift * worst - 0.5 * shift**2)
    return ratio / (1.0 + ratio)


def _passes(fit: Refined) -> bool:
    """
    Whether ``fit`` passes the chi-square check: its objective at most the 95 % point.

    Of chi-square with ``dof`` degrees of freedom (Wilson-Hilferty); False without any.
    """
    if fit.dof < 1:
        return False
    k = 2.0 / (9.0 * fit.dof)
    return fit.cost <= fit.dof * (1.0 - k + CHI2_Z95 * math.sqrt(k)) ** 3


def _evidence(fit: Refined) -> float:
    """Return the log Laplace evidence of a fit, (logdet - cost) / 2 (+ a shared constant)."""
    return 0.5 * (fit.logdet - fit.cost)


def _by_evidence(fits: list) -> list[tuple[float, Refined]]:
    """
    Return [(weight, fit)]: ``fits`` of the same fixes weighted by their Laplace evidence.

    The weights sum to one; a fit of weight below 1e-6 is left out; a lone fit weighs 1.
    """
    if len(fits) == 1:
        return [(1.0, fits[0])]
    evidence = np.array([_evidence(f) for f in fits])
    weights = np.exp(evidence - evidence.max())
    return [(float(w), f) for w, f in zip(weights / weights.sum(), fits) if w >= 1e-6]


def _basins(fit: Refined | None, others: list, reach: float,
            most: int = MAX_BASINS) -> list[Refined]:
    """
    Return the fits of ``others`` in basins of their own within ``reach`` of ``fit``'s evidence.

    Within reach: -2 log evidence at most ``reach`` above ``fit``'s (13.8: weight 1/1000 of
    its). Two fits share a basin when their states at the last fix (position, velocity, spin
    momentum h) lie within one sigma of each other (Mahalanobis under the sum of their
    covariances; a fit converges to a tenth of its sigma, :data:`.refine.CONVERGED`). One fit
    a basin, the most evident; at most ``most``, the most evident first.
    """
    if fit is None or reach <= 0.0 or not math.isfinite(fit.logdet):
        return []
    top = _evidence(fit)
    out = []
    for other in sorted((o for o in others if o is not None and math.isfinite(o.logdet)),
                        key=lambda o: -_evidence(o)):
        if 2.0 * (top - _evidence(other)) > reach or len(out) >= most:
            break
        if not any(_same_basin(other, kept) for kept in [fit] + out):
            out.append(other)
    return out


def _same_basin(a: Refined, b: Refined) -> bool:
    """Whether fits ``a`` and ``b`` sit in one basin (:func:`_basins`)."""
    idx = np.r_[X_R:X_V + 3, X_H:X_H + 3]
    d = a.x[idx] - b.x[idx]
    cov = a.P[np.ix_(idx, idx)] + b.P[np.ix_(idx, idx)]
    return float(d @ np.linalg.lstsq(cov, d, rcond=1e-12)[0]) < 1.0


def _least(a: Refined | None, b: Refined | None) -> Refined | None:
    """Return the fit of lower objective of ``a`` and ``b`` (either may be None)."""
    if a is None or b is None:
        return a if b is None else b
    return a if a.cost <= b.cost else b


def _reversed(x0: np.ndarray) -> np.ndarray:
    """Return the state ``x0`` with its spin h [rad/s] reversed (the other hand's start)."""
    out = np.array(x0, dtype=float)
    out[X_H:X_H + 3] *= -1.0
    return out


def _mix(parts) -> tuple[np.ndarray, np.ndarray]:
    """Return the (mean, cov) of a mixture of [(weight, (mean, cov))] (weights any scale)."""
    wsum = sum(w for w, _ in parts)
    mean = sum(w * m[0] for w, m in parts) / wsum
    return mean, sum(w * (m[1] + np.outer(m[0] - mean, m[0] - mean)) for w, m in parts) / wsum


def _mix_planes(weighted: list) -> list:
    """
    Mix moments plane by plane: ``weighted`` [(weight, [(mean, cov) or None per plane])].

    Returns [(mean, cov) or None] per plane (None where a part missed it).
    """
    return [
        None if not weighted or any(m[k] is None for _, m in weighted)
        else _mix([(w, m[k]) for w, m in weighted])
        for k in range(len(PLANE_COLUMNS))
    ]


def _same(entry: _Entry, t: float, meas: Measurement) -> bool:
    """
    Tell whether the fix (``t``, ``meas``) is the one ``entry`` holds.

    Another detection in the same frame (clutter, a second ball) is not a duplicate.
    """
    z = entry.meas.z
    return (
        abs(entry.stamp - t) < 1e-9
        and z.size == meas.z.size
        and bool(np.all(np.abs(z - meas.z) < 1e-9))
    )


def measured_jitter(stamps, min_gaps: int = 8) -> float:
    """
    Return the jitter [s, 1 sigma] of a camera's stamps [s], from the spread of their spacing.

    A regular camera's stamps are k T + e_k: the spacing of stamps L apart spreads by sqrt(2)
    sigma_e. Robust (median absolute deviation, distinct stamps): dropped frames and a second
    detection in a frame do not count; the largest over L = 1, 2, 3, since a jitter near T
    reorders neighbours (and narrows their sorted spacing). 0 with fewer than ``min_gaps``
    spacings.
    """
    t = np.unique(np.asarray(stamps, dtype=float))
    if t.size - 1 < min_gaps:
        return 0.0
    out = 0.0
    for lag in (1, 2, 3):
        gaps = t[lag:] - t[:-lag]
        if gaps.size >= min_gaps:
            out = max(out, float(np.median(np.abs(gaps - np.median(gaps)))))
    return 1.4826 * out / math.sqrt(2.0)


def _one_per_stamp(times: np.ndarray, err: np.ndarray, limit: float) -> np.ndarray:
    """Return the indices with ``err`` <= ``limit``, the smallest error for each stamp."""
    ok = np.flatnonzero(err <= limit)
    chosen: dict = {}
    for k in ok:
        key = round(float(times[k]), 9)
        if key not in chosen or err[k] < err[chosen[key]]:
            chosen[key] = k
    return np.array(sorted(chosen.values()), dtype=int)
