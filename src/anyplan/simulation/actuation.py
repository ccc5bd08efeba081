"""Imperfect execution: the robot does not drive exactly the twist it achieves on paper.

A real base slips, its wheels see uneven ground and its odometry does not see that, so the robot
moves by a twist that differs from the one its drive achieves, by an error that persists over
fractions of a second and grows with the motion. :class:`ActuationNoise` moves the pose by the
achieved (clipped) twist plus a first-order Gauss-Markov error per axis (correlation time
``tau_s``; :class:`~anyplan.simulation.gauss_markov.GaussMarkov`) whose spreads, ``sigma_v``
[m/s] and ``sigma_omega`` [rad/s] at full speed or turn rate, scale with ``min(1, |v| / v_max +
|omega| / omega_max)``: a robot at rest does not drift (the error grows with the motion, as in
the velocity motion model of Thrun, Burgard & Fox, *Probabilistic Robotics*, 2005, section 5.3).
The twist stays within ``v_max`` and ``omega_max`` (at full speed the error can only slow the
robot). The state reports the drive's twist (what odometry measures); the agent sees the pose
the robot really reached. Seeded per run, on a stream of its own.
"""

from __future__ import annotations

from dataclasses import replace

from anyplan.simulation.gauss_markov import GaussMarkov
from anyplan.world.robot import Command, RobotSpec, RobotState, clip_command

__all__ = ["ACTUATION_STREAM", "ACTUATION_TAU_S", "ActuationNoise"]

#: The second entry of the actuation generator's seed, ``default_rng((seed, ACTUATION_STREAM))``
#: (the sensor's noise has a stream of its own).
ACTUATION_STREAM = 0xAC7

#: Correlation time [s] of the execution error: slip and lag last a few control periods.
ACTUATION_TAU_S = 0.5


class ActuationNoise(GaussMarkov):
    """The execution error of one run.

    Args:
        sigma_v: Stationary standard deviation [m/s] of the speed error at full motion (>= 0).
        sigma_omega: Stationary standard deviation [rad/s] of the turn-rate error at full
            motion (>= 0).
        seed: The run's seed.
        tau_s: Correlation time [s] of both errors (> 0).

    Examples:
        The same seed draws the same errors:

        >>> from anyplan.world.robot import RobotSpec
        >>> spec = RobotSpec((0.0, 0.0, 0.0), (5.0, 0.0), radius=0.3, v_max=1.0, omega_max=1.0,
        ...                  a_max=1.0, alpha_max=2.0)
        >>> runs = [ActuationNoise(0.1, 0.1, seed=3) for _ in range(2)]
        >>> s = [RobotState(0.0, 0.0, 0.0, 0.5, 0.0)] * 2
        >>> for _ in range(10):
        ...     s = [n.step(spec, x, Command(0.5, 0.0), 0.05) for n, x in zip(runs, s)]
        >>> s[0] == s[1] and s[0].x != 0.5 * 10 * 0.05
        True
    """

    def __init__(self, sigma_v: float, sigma_omega: float, seed: int,
                 tau_s: float = ACTUATION_TAU_S) -> None:
        # the stationary state: the first step's error is drawn from the process's own spread
        super().__init__(("sigma_v", "sigma_omega"), (sigma_v, sigma_omega), seed, ACTUATION_STREAM,
                         tau_s)
        #: The twist the robot moved by in the last step (the drive's plus the error).
        self.ground = Command(0.0, 0.0)

    def record(self) -> dict[str, object]:
        """What to store in ``result.extra["actuation"]``."""
        return {"sigma_v_mps": float(self.sigma[0]), "sigma_omega_radps": float(self.sigma[1]),
                "tau_s": self.tau_s, "seed": list(self.seed_sequence)}

    def step(self, spec: RobotSpec, state: RobotState, cmd: Command, dt: float) -> RobotState:
        """Advance the robot by ``dt`` [s]: the drive achieves ``cmd`` clipped to the limits
        (:func:`~anyplan.world.robot.clip_command`), the pose moves by that twist plus this
        step's error scaled by the motion, held within ``v_max`` and ``omega_max`` (the
        unicycle integrated exactly), and the state reports the drive's twist."""
        self.advance(dt)
        c = clip_command(spec, state, cmd, dt)
        scale = min(1.0, abs(c.v) / spec.v_max + abs(c.omega) / spec.omega_max)
        v = min(max(c.v + scale * float(self.error[0]), -spec.v_max), spec.v_max)
        w = min(max(c.omega + scale * float(self.error[1]), -spec.omega_max), spec.omega_max)
        self.ground = Command(v, w)
        return replace(state.moved(v, w, dt), v=c.v, omega=c.omega)
