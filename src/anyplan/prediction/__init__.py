"""What a planner believes the moving obstacles will do.

Planners never read the simulator's ground truth. Each control step the simulator hands the
agent :class:`ObstacleObservation` records (the obstacles it can see, with their current pose
and twist); a predictor turns them into :class:`PredictedObstacle` motions over future time.
"""

from anyplan.prediction.base import (
    ConstantTwistPredictor,
    ObstacleObservation,
    PredictedObstacle,
    Predictor,
)

__all__ = ["ConstantTwistPredictor", "ObstacleObservation", "PredictedObstacle", "Predictor"]
