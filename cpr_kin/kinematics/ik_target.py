"""Where the tool frame must go: :class:`IkTarget`, a position or a pose within tolerances.

A goal is checked against it by forward kinematics (:meth:`IkTarget.reached`), whichever IK
found the configuration: a robot's own analytic IK or :func:`cpr_kin.solve_ik`
(:mod:`cpr_kin.kinematics.numerical_ik`, imported only where it runs).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin
from numpy.typing import NDArray

from cpr_kin.common.errors import CprKinError

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class IkTarget:
    """Where the tool frame must go.

    Attributes:
        position: ``(3,)`` position in the base frame [m].
        rotation: ``(3, 3)`` orientation, or ``None`` for a position goal.
        tolerance_m: largest position error accepted [m].
        tolerance_rad: largest rotation error accepted [rad] (a pose goal).
    """

    position: FloatArray
    rotation: FloatArray | None = None
    tolerance_m: float = 1e-4
    tolerance_rad: float = 1e-3

    def __post_init__(self) -> None:
        position = np.asarray(self.position, dtype=float)
        if position.shape != (3,) or not np.all(np.isfinite(position)):
            raise CprKinError(
                f"IK target position {np.asarray(self.position).tolist()} must be three finite numbers [m]"
            )
        object.__setattr__(self, "position", position)
        if self.rotation is not None:
            rotation = np.asarray(self.rotation, dtype=float)
            if rotation.shape != (3, 3) or not np.allclose(rotation @ rotation.T, np.eye(3), atol=1e-6):
                raise CprKinError("IK target rotation must be a 3 x 3 rotation matrix")
            object.__setattr__(self, "rotation", rotation)
        if not (self.tolerance_m > 0 and self.tolerance_rad > 0):
            raise CprKinError(f"IK tolerances {self.tolerance_m} m, {self.tolerance_rad} rad must be > 0")

    def errors(self, placement: pin.SE3) -> tuple[float, float]:
        """Position [m] and rotation [rad] error of a frame placement."""
        position = float(np.linalg.norm(placement.translation - self.position))
        if self.rotation is None:
            return position, 0.0
        rotation = float(np.linalg.norm(pin.log3(self.rotation.T @ placement.rotation)))
        return position, rotation

    def reached(self, placement: pin.SE3) -> bool:
        """Whether ``placement`` is within the tolerances."""
        position, rotation = self.errors(placement)
        return position <= self.tolerance_m and rotation <= self.tolerance_rad

    def miss(self, placement: pin.SE3) -> str:
        """How far ``placement`` is from the target, against the tolerances, in words."""
        position, rotation = self.errors(placement)
        text = f"{position:.4g} m from the position (tolerance {self.tolerance_m:g} m)"
        if self.rotation is not None:
            text += f", {rotation:.4g} rad from the orientation (tolerance {self.tolerance_rad:g} rad)"
        return text

    def excess(self, placement: pin.SE3) -> float:
        """The larger of the position and rotation errors, each over its tolerance (<= 1: reached)."""
        position, rotation = self.errors(placement)
        return max(position / self.tolerance_m, rotation / self.tolerance_rad)
