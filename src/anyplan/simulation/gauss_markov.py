"""A seeded first-order Gauss-Markov process per axis: the simulator's slowly wandering errors.

Each axis's error follows ``e' = -e / tau_s + white noise`` (Maybeck, *Stochastic Models,
Estimation and Control*, vol. 1, 1979, section 4.11), sampled exactly at each step ``dt``:
``e <- rho e + sqrt(1 - rho^2) sigma n`` with ``rho = exp(-dt / tau_s)`` and ``n`` standard normal,
starting from its stationary spread ``sigma``. The execution error
(:class:`~anyplan.simulation.actuation.ActuationNoise`) and the localization error
(:class:`~anyplan.simulation.localization.LocalizationError`) are such processes, each on a
stream of the run's seed of its own.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

__all__ = ["GaussMarkov"]


class GaussMarkov:
    """The process's state and generator (see the module docstring).

    Args:
        names: The setting each axis's spread comes from, for the error message (an axis may
            share one with another).
        sigmas: Stationary standard deviation of each axis (>= 0, in its axis's unit).
        seed: The run's seed.
        stream: The second entry of the generator's seed, ``default_rng((seed, stream))``.
        tau_s: Correlation time [s] (> 0).

    Raises:
        ValueError: a spread below 0 or not finite, or a correlation time not above 0, named.

    Attributes:
        sigma: The spreads (n,).
        tau_s: The correlation time [s].
        seed_sequence: ``(seed, stream)``.
        rng: The generator.
        error: The current error (n,), first drawn from the stationary spread.
    """

    def __init__(self, names: Sequence[str], sigmas: Sequence[float], seed: int, stream: int,
                 tau_s: float) -> None:
        for name, val in zip(names, sigmas, strict=True):
            if not (math.isfinite(val) and val >= 0.0):
                raise ValueError(f"{name}: must be >= 0, got {val!r}")
        if not (math.isfinite(tau_s) and tau_s > 0.0):
            raise ValueError(f"tau_s: must be > 0, got {tau_s!r}")
        self.sigma = np.array([float(s) for s in sigmas])
        self.tau_s = float(tau_s)
        self.seed_sequence = (int(seed), stream)
        self.rng = np.random.default_rng(list(self.seed_sequence))
        self.error = self.sigma * self.rng.standard_normal(len(self.sigma))

    def advance(self, dt: float) -> None:
        """Advance the error by ``dt`` [s]."""
        rho = math.exp(-dt / self.tau_s)
        self.error = (rho * self.error
                      + math.sqrt(1.0 - rho * rho) * self.sigma * self.rng.standard_normal(len(self.sigma)))
