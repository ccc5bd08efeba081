"""BIT*'s settings (:class:`BITStarConfig`)."""

from __future__ import annotations

from dataclasses import dataclass

from anyplan.config import setting, validate

__all__ = ["BITStarConfig"]


@dataclass(frozen=True)
class BITStarConfig:
    """BIT* settings.

    Attributes:
        samples_per_batch: Samples added per batch, >= 1. OMPL's default is 100; with the
            compiled search, 400 converges faster per second on our benchmark problems
            (``benchmarks/bitstar.py``) while the first solution still takes ~1 ms.
        first_batch_samples: Samples of the first batch (0: same as ``samples_per_batch``).
        rewire_factor: ``eta``, the factor on the RGG radius (or k), in [1.0, 3.0]; 1.1 as in
            OMPL.
        use_k_nearest: Connect to the k nearest points instead of an r-disc.
        prune: Drop samples and vertices that cannot improve the solution at each new batch.
        chunk_s: Target wall time [s] between two checks of the termination condition.
    """

    samples_per_batch: int = setting(400, lo=1, doc="samples added per batch")
    first_batch_samples: int = setting(0, lo=0, doc="samples of the first batch (0: samples_per_batch)")
    rewire_factor: float = setting(1.1, lo=1.0, hi=3.0, doc="eta, the factor on the RGG radius")
    use_k_nearest: bool = setting(False, doc="k nearest instead of an r-disc")
    prune: bool = setting(True, doc="drop what cannot improve the solution")
    chunk_s: float = setting(2e-4, lo=0.0, lo_open=True, hi=1.0, unit="s",
                             doc="wall time between termination checks")

    def __post_init__(self) -> None:
        validate(self, owner="")  # messages "rewire_factor: must be in [1, 3], got 5.0"
