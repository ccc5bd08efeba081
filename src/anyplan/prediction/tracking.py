"""Tracking moving obstacles from noisy position detections: an IMM of two Kalman filters.

Each obstacle has a state ``[x, y, vx, vy, omega]`` (m, m/s, rad/s) estimated by an interacting
multiple model (Blom & Bar-Shalom, IEEE TAC 1988) of a constant-velocity (CV) and a
coordinated-turn (CT, extended Kalman) filter that switch at ``switch_rate`` [1/s];
measurements are positions with noise ``sigma_m`` [m] per axis. Named detections go to their
obstacle's track; anonymous ones (no name, some false) are associated by global nearest
neighbour within the gate (optimal assignments on the innovations' likelihood, established
tracks first), and a track they start is reported only once confirmed (``confirm_hits``
updates) and kept unseen as long as its detections have earned. Tracks coast while hidden,
up to ``drop_after_s``, and go after ``visible_misses`` frames missed in plain view.
Everything is vectorised over tracks.

The models and their noise terms: ``docs/perception.md``, "The IMM tracker" and "Anonymous
detections".
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass, replace

import numpy as np

from anyplan.config import SettingError, setting, validate
from anyplan.prediction.detection import Detection

__all__ = ["TrackerConfig", "Tracker", "TrackEstimate", "ct_transition", "Expected"]

#: What the sensor should have detected in a frame: predicted centres (N, 2) [m], radii (N,)
#: [m] -> mask (N,).
Expected = Callable[[np.ndarray, np.ndarray], np.ndarray]

_H = np.zeros((2, 5))
_H[0, 0] = _H[1, 1] = 1.0


@dataclass(frozen=True)
class TrackerConfig:
    """Tracker settings (SI units).

    Attributes:
        sigma_m: Measurement noise [m] per axis (the sensor's); floored at 1 mm.
        q_cv: Acceleration noise density of the CV model [m^2/s^3].
        q_ct: Acceleration noise density of the CT model [m^2/s^3].
        q_omega: Turn-rate random walk density of the CT model [rad^2/s^3].
        switch_rate: Model switching rate [1/s].
        init_speed_sigma: Velocity standard deviation [m/s] of a new track.
        drop_after_s: A track not detected for this long [s] is dropped.
        gate_m: A detection farther than this [m] from its track's predicted position, and
            outside its ``gate_chi2`` gate under every model, restarts the track there (the
            obstacle jumped: a teleport is a leave and a new appearance, not a fast motion); an
            anonymous detection is associated only within it.
        gate_chi2: Squared Mahalanobis distance of that gate (2 degrees of freedom).
        manoeuvre_chi2: A detection inside the gate whose squared Mahalanobis distance
            exceeds this under every model marks a manoeuvre (an obstacle that turns back at a
            corner): the track's covariance then gets the extra acceleration noise
            ``q_manoeuvre`` over the frame before the update, so that its velocity follows in
            a frame or two instead of about 0.6 s (adjustable process noise, Bar-Shalom, Li &
            Kirubarajan 2001, section 11.2). 9.2 is the 99 % gate of 2 degrees of freedom.
        q_manoeuvre: That extra acceleration noise density [m^2/s^3] (0: never). 50 lets the
            velocity change by about 2.2 m/s (one sigma) in a 0.1 s frame.
        confirm_hits: Anonymous detections: a track is reported (confirmed) once it has had
            this many detections; a false detection rarely has a second one in its gate.
        tentative_drop_s: Anonymous detections: a track is dropped when not detected for
            ``tentative_drop_s`` x (its detections / ``confirm_hits``) [s], at least this and
            at most ``drop_after_s`` (a track earns its patience: a false one confirmed by
            chance is dropped about as fast as an unconfirmed one).
        urgent_gap_m: Anonymous detections: a track not yet confirmed whose last detection
            is within this gap [m] of the robot's disc is shown to the planner at once
            (``TrackingAgent``; 0: never): near the robot a false track costs a brake, a person
            shown a frame late a collision.
        init_max_speed: Anonymous detections: a track not yet confirmed takes a detection
            only within this speed [m/s] (plus 4 noise sigmas) of its last one: its velocity is
            still a guess and its gate would be metres wide (two-point initiation with a
            velocity gate, Blackman & Popoli 1999, section 6.3).
        visible_misses: A track the sensor should have detected (its predicted centre in view,
            no other track in the way: ``update``'s ``expected``) and did not, this many frames
            in a row, is dropped (0: never): a track's absence where the sensor looks is
            evidence that the obstacle is gone (negative information; an obstacle that left or
            jumped), where a hidden one coasts up to ``drop_after_s``. Frames where the track
            is not expected neither count nor reset the count.
        view_margin_m: A track is expected (``visible_misses``) only when its predicted centre
            is in view with this to spare [m]: inside the range by it, clear of the static
            obstacles and of the other tracks' discs by more (near the view's edges the
            prediction and the truth may lie on either side).
    """

    sigma_m: float = setting(0.05, lo=0.0, hi=10.0, unit="m", doc="measurement noise per axis")
    q_cv: float = setting(0.05, lo=0.0, lo_open=True, hi=1e4, unit="m^2/s^3", doc="CV acceleration noise")
    q_ct: float = setting(0.05, lo=0.0, lo_open=True, hi=1e4, unit="m^2/s^3", doc="CT acceleration noise")
    q_omega: float = setting(0.02, lo=0.0, lo_open=True, hi=1e3, unit="rad^2/s^3",
                             doc="CT turn-rate random walk")
    switch_rate: float = setting(0.5, lo=0.0, hi=1e3, unit="1/s", doc="model switching rate")
    init_speed_sigma: float = setting(1.0, lo=0.0, lo_open=True, hi=100.0, unit="m/s",
                                      doc="velocity sigma of a new track")
    drop_after_s: float = setting(2.0, lo=0.0, lo_open=True, hi=3600.0, unit="s",
                                  doc="a track unseen this long is dropped")
    gate_m: float = setting(1.0, lo=0.0, lo_open=True, hi=100.0, unit="m",
                            doc="a detection this far outside the gate restarts its track")
    gate_chi2: float = setting(25.0, lo=0.0, lo_open=True, hi=1e6, unit="",
                               doc="squared Mahalanobis gate of the restart")
    manoeuvre_chi2: float = setting(9.2, lo=0.0, lo_open=True, hi=1e6, unit="",
                                    doc="squared Mahalanobis distance that marks a manoeuvre")
    q_manoeuvre: float = setting(50.0, lo=0.0, hi=1e6, unit="m^2/s^3",
                                 doc="acceleration noise added at a manoeuvre")
    confirm_hits: float = setting(2.0, lo=1.0, hi=100.0, unit="",
                                  doc="anonymous: detections that confirm a track")
    tentative_drop_s: float = setting(0.3, lo=0.0, lo_open=True, hi=3600.0, unit="s",
                                      doc="anonymous: patience per confirm_hits detections")
    urgent_gap_m: float = setting(1.0, lo=0.0, hi=100.0, unit="m",
                                  doc="anonymous: young tracks this near the robot are shown")
    init_max_speed: float = setting(3.0, lo=0.0, lo_open=True, hi=100.0, unit="m/s",
                                    doc="anonymous: fastest an unconfirmed track may move")
    visible_misses: float = setting(3.0, lo=0.0, hi=1000.0, unit="",
                                    doc="frames missed in view that drop a track (0: never)")
    view_margin_m: float = setting(0.2, lo=0.0, hi=10.0, unit="m",
                                   doc="a track is expected in view only with this to spare")

    def __post_init__(self) -> None:
        validate(self)
        for name in ("confirm_hits", "visible_misses"):  # counts, kept floats like the others
            if not float(getattr(self, name)).is_integer():
                raise SettingError("TrackerConfig", name,
                                   f"must be a whole number, got {getattr(self, name)!r}")


@dataclass(frozen=True)
class TrackEstimate:
    """One track at time ``t`` [s]: mean state, its covariance and the model probabilities.

    Attributes:
        name: Obstacle name (``track-K`` for a track of anonymous detections).
        t: Time [s] of the estimate.
        state: ``[x, y, vx, vy, omega]`` (m, m/s, rad/s).
        cov: 5 x 5 covariance.
        mode_probs: (P(CV), P(CT)).
        radius: Disc radius [m] from the detections.
        last_seen: Time [s] of the last detection.
        n_updates: Number of detections used.
        model_states: The two models' states (2, 5): CV, CT.
    """

    name: str
    t: float
    state: np.ndarray
    cov: np.ndarray
    mode_probs: np.ndarray
    radius: float
    last_seen: float
    n_updates: int
    model_states: np.ndarray | None = None

    @property
    def turn_rate(self) -> float:
        """The CT model's turn rate [rad/s] (the mixture's omega is diluted by CV's zero)."""
        return float(self.model_states[1, 4]) if self.model_states is not None else float(self.state[4])

    @property
    def speed(self) -> float:
        """Estimated speed [m/s]."""
        return float(math.hypot(self.state[2], self.state[3]))

    @property
    def heading(self) -> float:
        """Estimated heading [rad] (of the velocity)."""
        return float(math.atan2(self.state[3], self.state[2]))


def ct_transition(x: np.ndarray, T: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Coordinated-turn step of states ``x`` (N, 5) by ``T`` (N,) [s]: (new states, Jacobians
    (N, 5, 5)). Stable as omega -> 0 (series below |omega T| = 1e-4)."""
    vx, vy, w = x[:, 2], x[:, 3], x[:, 4]
    wt = w * T
    s, c = np.sin(wt), np.cos(wt)
    small = np.abs(wt) < 1e-4
    ws = np.where(small, 1.0, w)
    A = np.where(small, T - w * w * T ** 3 / 6.0, s / ws)            # sin(wT) / w
    B = np.where(small, w * T * T / 2.0, (1.0 - c) / ws)             # (1 - cos wT) / w
    dA = np.where(small, -w * T ** 3 / 3.0, (T * c * ws - s) / (ws * ws))
    dB = np.where(small, T * T / 2.0 - w * w * T ** 4 / 8.0, (T * s * ws - (1.0 - c)) / (ws * ws))
    out = np.empty_like(x)
    out[:, 0] = x[:, 0] + A * vx - B * vy
    out[:, 1] = x[:, 1] + B * vx + A * vy
    out[:, 2] = c * vx - s * vy
    out[:, 3] = s * vx + c * vy
    out[:, 4] = w
    F = np.zeros((len(x), 5, 5))
    F[:, 0, 0] = F[:, 1, 1] = F[:, 4, 4] = 1.0
    F[:, 0, 2], F[:, 0, 3], F[:, 0, 4] = A, -B, dA * vx - dB * vy
    F[:, 1, 2], F[:, 1, 3], F[:, 1, 4] = B, A, dB * vx + dA * vy
    F[:, 2, 2], F[:, 2, 3], F[:, 2, 4] = c, -s, -T * (s * vx + c * vy)
    F[:, 3, 2], F[:, 3, 3], F[:, 3, 4] = s, c, T * (c * vx - s * vy)
    return out, F


def _inv2(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Inverses and determinants of 2 x 2 matrices S (..., 2, 2), written out: LAPACK's
    (``np.linalg.inv``, ``det``) run BLAS kernels chosen for the CPU, and the same seeded run
    gave other tracks on another machine (``anyplan.geometry.se2``)."""
    a, b, c, d = S[..., 0, 0], S[..., 0, 1], S[..., 1, 0], S[..., 1, 1]
    det = a * d - b * c
    inv = np.empty_like(S)
    inv[..., 0, 0] = d / det
    inv[..., 0, 1] = -b / det
    inv[..., 1, 0] = -c / det
    inv[..., 1, 1] = a / det
    return inv, det


def _accel_q(T: np.ndarray, q: float) -> np.ndarray:
    """Discrete white-noise-acceleration covariance (N, 5, 5) on [x, y, vx, vy]."""
    Q = np.zeros((len(T), 5, 5))
    for i in (0, 1):
        Q[:, i, i] = q * T ** 3 / 3.0
        Q[:, i, i + 2] = Q[:, i + 2, i] = q * T ** 2 / 2.0
        Q[:, i + 2, i + 2] = q * T
    return Q


class Tracker:
    """IMM (CV + CT) tracks of obstacles, from named or anonymous detections.

    Args:
        config: Filter settings.
    """

    def __init__(self, config: TrackerConfig | None = None) -> None:
        # scipy.optimize takes about 0.2 s to import: a run that tracks nothing (oracle or
        # twist perception) never loads it; one that tracks loads it here, before planning
        from scipy.optimize import linear_sum_assignment

        self._assign = linear_sum_assignment
        self.config = config or TrackerConfig()
        self.names: list[str] = []
        self.x = np.zeros((0, 2, 5))
        self.P = np.zeros((0, 2, 5, 5))
        self.mu = np.zeros((0, 2))
        self.t = np.zeros(0)          # filter time of each track [s]
        self.last_seen = np.zeros(0)  # time of the last detection [s]
        self.radius = np.zeros(0)
        self.n = np.zeros(0, dtype=int)
        self.confirmed = np.zeros(0, dtype=bool)  # reported by estimates()
        self.last_z = np.zeros((0, 2))  # the last detection's position [m]
        self.born_named = np.zeros(0, dtype=bool)  # started by a named detection
        self.missed = np.zeros(0, dtype=int)  # frames in a row expected in view and missed
        self.started = 0  # tracks started from anonymous detections (their names: track-K)
        self.dropped = 0  # confirmed tracks dropped
        self.discarded = 0  # tracks dropped before confirmation (anonymous: mostly clutter)
        self.restarted = 0  # tracks restarted at a detection outside their gate (jumps)
        self.vanished = 0  # tracks dropped after visible_misses frames missed in view
        self.manoeuvres = 0  # updates that got the manoeuvre noise

    def __len__(self) -> int:
        """The number of confirmed tracks (every track of named detections)."""
        return int(self.confirmed.sum())

    # --- filter steps ----------------------------------------------------------------------------
    def _predict(self, idx: np.ndarray, t: float) -> np.ndarray:
        """IMM mixing and prediction of tracks ``idx`` to time ``t``; the prediction steps
        [s], per track."""
        if len(idx) == 0:
            return np.zeros(0)
        cfg = self.config
        T = np.maximum(t - self.t[idx], 0.0)
        x, P, mu = self.x[idx], self.P[idx], self.mu[idx]
        p_sw = 1.0 - np.exp(-cfg.switch_rate * T)
        trans = np.empty((len(idx), 2, 2))              # trans[n, i, j] = P(j | i)
        trans[:, 0, 0] = trans[:, 1, 1] = 1.0 - p_sw
        trans[:, 0, 1] = trans[:, 1, 0] = p_sw
        c = np.einsum("ni,nij->nj", mu, trans)           # predicted model probabilities
        w = mu[:, :, None] * trans / np.maximum(c[:, None, :], 1e-300)  # w[n, i, j] = mu_{i|j}
        x0 = np.einsum("nij,nik->njk", w, x)
        d = x[:, :, None, :] - x0[:, None, :, :]         # [n, i, j, k]
        P0 = np.einsum("nij,nikl->njkl", w, P) + np.einsum("nij,nijk,nijl->njkl", w, d, d)
        # CV (model 0): omega reset to 0
        F = np.zeros((len(idx), 5, 5))
        F[:, 0, 0] = F[:, 1, 1] = F[:, 2, 2] = F[:, 3, 3] = 1.0
        F[:, 0, 2] = F[:, 1, 3] = T
        xcv = np.einsum("nkl,nl->nk", F, x0[:, 0])
        Qcv = _accel_q(T, cfg.q_cv)
        Qcv[:, 4, 4] = 1e-6
        Pcv = np.einsum("nab,nbc,ndc->nad", F, P0[:, 0], F) + Qcv
        xct, Fct = ct_transition(x0[:, 1], T)
        Qct = _accel_q(T, cfg.q_ct)
        Qct[:, 4, 4] = cfg.q_omega * T
        Pct = np.einsum("nab,nbc,ndc->nad", Fct, P0[:, 1], Fct) + Qct
        self.x[idx, 0], self.x[idx, 1] = xcv, xct
        self.P[idx, 0], self.P[idx, 1] = Pcv, Pct
        self.mu[idx] = c
        self.t[idx] = t
        return T

    def _r2(self) -> float:
        """Measurement variance [m^2] per axis (``sigma_m`` floored at 1 mm)."""
        return max(self.config.sigma_m, 1e-3) ** 2

    def _innovation_cov(self, P: np.ndarray) -> np.ndarray:
        """Innovation covariances S (..., 2, 2) of state covariances P (..., 5, 5)."""
        return P[..., :2, :2] + self._r2() * np.eye(2)

    def _innovation(self, x: np.ndarray, P: np.ndarray, z: np.ndarray
                    ) -> tuple[np.ndarray, np.ndarray]:
        """Innovations y (N, 2 models, 2) of positions z (N, 2) against states x (N, 2, 5) with
        covariances P (N, 2, 5, 5), and their covariances S (N, 2, 2, 2)."""
        return z[:, None, :] - x[:, :, :2], self._innovation_cov(P)

    def _predicted(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Every track's model states (N, 2, 5), covariances (N, 2, 5, 5) and model
        probabilities (N, 2) predicted to time ``t`` [s]; the filter itself is not changed."""
        saved = (self.x.copy(), self.P.copy(), self.mu.copy(), self.t.copy())
        self._predict(np.flatnonzero(self.t < t), t)
        out = self.x, self.P, self.mu
        self.x, self.P, self.mu, self.t = saved
        return out

    def _squared_distances(self, idx: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Squared Mahalanobis distances (N, 2) of positions z (N, 2) from tracks ``idx``
        (predicted to the detection time) under each model."""
        y, S = self._innovation(self.x[idx], self.P[idx], z)
        return np.asarray(np.einsum("nma,nmab,nmb->nm", y, _inv2(S)[0], y))

    def _update(self, idx: np.ndarray, z: np.ndarray) -> None:
        """Kalman update of tracks ``idx`` (already at the detection time) with positions z (N, 2)."""
        x, P = self.x[idx], self.P[idx]
        y, S = self._innovation(x, P, z)
        Sinv, det = _inv2(S)
        K = np.einsum("nmab,nmbc->nmac", P[:, :, :, :2], Sinv)   # (n, m, 5, 2)
        x = x + np.einsum("nmab,nmb->nma", K, y)
        P = P - np.einsum("nmab,nmbc->nmac", K, P[:, :, :2, :])
        P = 0.5 * (P + np.swapaxes(P, -1, -2))
        md = np.einsum("nma,nmab,nmb->nm", y, Sinv, y)
        lik = np.exp(-0.5 * np.minimum(md, 700.0)) / (2 * math.pi * np.sqrt(det))
        mu = self.mu[idx] * (lik + 1e-300)
        self.mu[idx] = mu / mu.sum(axis=1, keepdims=True)
        self.x[idx], self.P[idx] = x, P

    def _initial(self, d: Detection) -> tuple[np.ndarray, np.ndarray]:
        """State and covariance of a track starting at detection ``d`` (at rest, uncertain)."""
        cfg = self.config
        r2 = self._r2()
        x = np.array([d.x, d.y, 0.0, 0.0, 0.0])
        P = np.diag([r2, r2, cfg.init_speed_sigma ** 2, cfg.init_speed_sigma ** 2, 0.3 ** 2])
        return x, P

    def _outside_gate(self, idx: np.ndarray, z: np.ndarray, md: np.ndarray) -> np.ndarray:
        """Tracks ``idx`` (predicted to the detection time) whose detection z (N, 2) is farther
        than ``gate_m`` from the predicted position and outside the gate of every model (``md``:
        their :meth:`_squared_distances`)."""
        cfg = self.config
        y = z[:, None, :] - self.x[idx][:, :, :2]
        far = np.hypot(y[..., 0], y[..., 1]).min(axis=1) > cfg.gate_m
        return far & (md.min(axis=1) > cfg.gate_chi2)

    def _add(self, d: Detection, confirmed: bool) -> None:
        x, P = self._initial(d)
        assert d.name is not None
        self.names.append(d.name)
        self.confirmed = np.append(self.confirmed, confirmed)
        self.born_named = np.append(self.born_named, confirmed)
        self.missed = np.append(self.missed, 0)
        self.last_z = np.concatenate([self.last_z, [[d.x, d.y]]])
        self.x = np.concatenate([self.x, np.broadcast_to(x, (1, 2, 5))])
        self.P = np.concatenate([self.P, np.broadcast_to(P, (1, 2, 5, 5))])
        self.mu = np.concatenate([self.mu, [[0.8, 0.2]]])
        self.t = np.append(self.t, d.t)
        self.last_seen = np.append(self.last_seen, d.t)
        self.radius = np.append(self.radius, d.radius)
        self.n = np.append(self.n, 1)

    def _drop(self, keep: np.ndarray) -> None:
        self.dropped += int((~keep & self.confirmed).sum())
        self.discarded += int((~keep & ~self.confirmed).sum())
        self.names = [n for n, k in zip(self.names, keep, strict=True) if k]
        self.x, self.P, self.mu = self.x[keep], self.P[keep], self.mu[keep]
        self.t, self.last_seen = self.t[keep], self.last_seen[keep]
        self.radius, self.n = self.radius[keep], self.n[keep]
        self.confirmed, self.last_z = self.confirmed[keep], self.last_z[keep]
        self.born_named, self.missed = self.born_named[keep], self.missed[keep]

    def _associate(self, t: float, dets: list[Detection], taken: set[int]
                   ) -> tuple[list[tuple[int, int]], list[int]]:
        """Global nearest neighbour of anonymous detections ``dets`` at ``t`` [s] to the tracks
        not in ``taken``: ``(pairs (detection, track), unpaired detections)``. A pair is
        admissible within ``gate_m`` of the track's predicted position (under one of the
        models: a reversal at a corner stays in it; the covariance's gate would grow metres
        wide while a track coasts, and clutter would keep it alive), and for a track not yet
        confirmed within ``init_max_speed`` of its last detection. The confirmed tracks are
        assigned first, the others then to the detections left (a matching cascade: a young track's wide
        covariance must not win a detection from an established one); each step takes the
        assignment with the most admissible pairs and then the least cost, the negative log
        likelihood ``d2 + ln det S`` (the smaller of the two models') (scipy's
        ``linear_sum_assignment``). The filter is not changed."""
        cand = np.array([i for i in range(len(self.names)) if i not in taken], dtype=int)
        if len(cand) == 0:
            return [], list(range(len(dets)))
        cfg = self.config
        z = np.array([[d.x, d.y] for d in dets])
        x, P, _ = self._predicted(t)
        y = z[None, :, None, :] - x[cand][:, None, :, :2]                 # (tracks, dets, 2, 2)
        Sinv, det = _inv2(self._innovation_cov(P[cand]))                  # (tracks, 2, 2, 2)
        d2 = np.einsum("ndma,nmab,ndmb->ndm", y, Sinv, y)
        cost = (d2 + np.log(det)[:, None, :]).min(axis=2)
        ok = np.hypot(y[..., 0], y[..., 1]).min(axis=2) <= cfg.gate_m
        young = ~self.confirmed[cand]
        if young.any():
            reach = cfg.init_max_speed * (t - self.last_seen[cand]) + 4.0 * max(cfg.sigma_m, 1e-3)
            step = z[None, :, :] - self.last_z[cand][:, None, :]
            ok &= ~young[:, None] | (np.hypot(step[..., 0], step[..., 1]) <= reach[:, None])
        pairs: list[tuple[int, int]] = []
        free = np.ones(len(dets), dtype=bool)
        for stage in (~young, young):
            rows = np.flatnonzero(stage)
            cols = np.flatnonzero(free)
            if not len(rows) or not len(cols):
                continue
            sub_ok = ok[np.ix_(rows, cols)]
            if not sub_ok.any():
                continue
            sub = cost[np.ix_(rows, cols)]
            # an inadmissible pair costs more than all admissible ones together: the
            # assignment first has as few of them as it can, then the least cost
            lo = float(sub[sub_ok].min())
            big = 1.0 + float((sub[sub_ok] - lo).sum()) * 2.0 + 1e6
            r, c = self._assign(np.where(sub_ok, sub - lo, big))
            for a, b in zip(r, c, strict=True):
                if sub_ok[a, b]:
                    pairs.append((int(cols[b]), int(cand[rows[a]])))
                    free[cols[b]] = False
        return pairs, [j for j in range(len(dets)) if free[j]]

    # --- public ----------------------------------------------------------------------------------
    def update(self, t: float, detections: Iterable[Detection],
               expected: Expected | None = None) -> tuple[Detection, ...]:
        """One sensor frame at time ``t`` [s]: associate the anonymous detections
        (:meth:`_associate`), update the detected tracks, start new ones, coast the others and
        drop those unseen for ``drop_after_s`` (anonymous ones: the patience they earned,
        ``tentative_drop_s``), or missed ``visible_misses`` frames in a row where the sensor
        should have seen them: ``expected`` (predicted centres (N, 2), radii (N,) [m]) -> mask
        (N,) of the tracks it should have detected in this frame (e.g.
        :meth:`anyplan.world.view.FieldOfView.expected`); None (the default, also for a step
        that is no sensor frame): nothing is known of the tracks not detected.
        Returns the detections, an anonymous one named after the track it updated or started."""
        dets = list(detections)
        index = {n: i for i, n in enumerate(self.names)}
        upd = [(index[d.name], d) for d in dets if d.name is not None and d.name in index]
        new = [(d, True) for d in dets if d.name is not None and d.name not in index]
        labels = [d.name for d in dets]
        anon = [k for k, d in enumerate(dets) if d.name is None]
        if anon:
            pairs, rest = self._associate(t, [dets[k] for k in anon], {i for i, _ in upd})
            for j, i in pairs:
                upd.append((i, dets[anon[j]]))
                labels[anon[j]] = self.names[i]
            for j in rest:
                self.started += 1
                labels[anon[j]] = f"track-{self.started}"
                new.append((replace(dets[anon[j]], name=labels[anon[j]]), False))
        if upd:
            idx = np.array([i for i, _ in upd])
            steps = self._predict(idx, t)
            z = np.array([[d.x, d.y] for _, d in upd])
            md = self._squared_distances(idx, z)  # the gate's and the manoeuvre test's
            jumped = self._outside_gate(idx, z, md)
            for k in np.flatnonzero(jumped):  # restarted where it is now
                x0, P0 = self._initial(upd[k][1])
                self.x[idx[k]], self.P[idx[k]], self.mu[idx[k]] = x0, P0, (0.8, 0.2)
                self.n[idx[k]] = 0
                self.restarted += 1
            if (~jumped).any():
                ii, zz = idx[~jumped], z[~jumped]
                man = md[~jumped].min(axis=1) > self.config.manoeuvre_chi2
                if man.any() and self.config.q_manoeuvre > 0.0:
                    q = _accel_q(steps[~jumped][man], self.config.q_manoeuvre)
                    self.P[ii[man]] += q[:, None, :, :]  # both models
                    self.manoeuvres += int(man.sum())
                self._update(ii, zz)
            self.last_seen[idx] = t
            self.last_z[idx] = z
            self.n[idx] += 1
            self.radius[idx] = [d.radius for _, d in upd]
        if expected is not None and len(self.names):
            hit = np.zeros(len(self.names), dtype=bool)
            hit[[i for i, _ in upd]] = True
            x, _, mu = self._predicted(t)
            centres = np.einsum("nm,nmk->nk", mu, x[:, :, :2])
            seen_by_sensor = np.asarray(expected(centres, self.radius), dtype=bool)
            self.missed = np.where(hit, 0, self.missed + (seen_by_sensor & ~hit))
        for d, named in new:
            self._add(d, named)
        self.confirmed |= self.n >= int(self.config.confirm_hits)
        cfg = self.config
        # anonymous tracks earn their patience: tentative_drop_s per confirm_hits detections,
        # up to drop_after_s (a false track confirmed by chance dies as fast as a young one)
        earned = np.clip(cfg.tentative_drop_s * self.n / int(cfg.confirm_hits),
                         cfg.tentative_drop_s, cfg.drop_after_s)
        patience = np.where(self.born_named, cfg.drop_after_s, earned)
        keep = t - self.last_seen <= patience + 1e-9
        if cfg.visible_misses > 0.0:
            gone = self.missed >= int(cfg.visible_misses)
            self.vanished += int((gone & keep).sum())
            keep &= ~gone
        if not keep.all():
            self._drop(keep)
        return tuple(d if d.name is not None else replace(d, name=lab)
                     for d, lab in zip(dets, labels, strict=True))

    def estimates(self, t: float, near: tuple[float, float, float] | None = None
                  ) -> list[TrackEstimate]:
        """Every confirmed track predicted to time ``t`` [s] (the filter itself is not
        changed): the IMM combination of the models' means and covariances. ``near`` = (x, y,
        r) [m]: also the tracks not yet confirmed whose last detection lies within r of (x,
        y) (what is close to a robot is reported at once: a false one costs a brake, a person
        missed a collision)."""
        shown = self.confirmed
        if near is not None and len(self.names):
            d = np.hypot(self.last_z[:, 0] - near[0], self.last_z[:, 1] - near[1])
            shown = shown | (d <= near[2])
        if not shown.any():
            return []
        x, P, mu = self._predicted(t)
        xm = np.einsum("nm,nmk->nk", mu, x)
        d = x - xm[:, None, :]
        Pm = np.einsum("nm,nmkl->nkl", mu, P) + np.einsum("nm,nmk,nml->nkl", mu, d, d)
        return [TrackEstimate(n, t, xm[i], Pm[i], mu[i].copy(), float(self.radius[i]),
                              float(self.last_seen[i]), int(self.n[i]), x[i].copy())
                for i, n in enumerate(self.names) if shown[i]]
