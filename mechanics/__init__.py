"""Mechanics of stable pushing: pure numpy/shapely, no planner imports.

Modules follow the papers: :mod:`.twist` (signed CORs and twists), :mod:`.se2` (poses and the
exponential of a twist), :mod:`.slider` (the part), :mod:`.stable` (procedure STABLE),
:mod:`.steering` (a control box mapped onto the stable pushes).
"""

from .se2 import exp_twist, log_pose, relative_pose, wrap_angle
from .slider import Slider
from .stable import DEFAULT_TIP_FACTOR, StableRegion, stable_region
from .steering import StableSteering
from .twist import cor_to_twist, point_velocity, twist_to_cor

__all__ = [
    "DEFAULT_TIP_FACTOR",
    "Slider",
    "StableRegion",
    "StableSteering",
    "cor_to_twist",
    "exp_twist",
    "log_pose",
    "point_velocity",
    "relative_pose",
    "stable_region",
    "twist_to_cor",
    "wrap_angle",
]
