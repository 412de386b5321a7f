"""Mechanics of pushing: pure numpy/scipy/shapely, no planner imports.

Modules follow the papers. Lynch & Mason 1996: :mod:`.twist` (signed CORs and twists),
:mod:`.se2` (poses and the exponential of a twist), :mod:`.slider` (the part), :mod:`.stable`
(procedure STABLE), :mod:`.push_plane` (the chart of an edge's pushes), :mod:`.steering` (a control box mapped onto the stable pushes). Lynch 1992,
the general multi-contact analysis: :mod:`.cones` (polyhedral cones of twists and wrenches),
:mod:`.contacts` (contact configurations), :mod:`.kinematics` (Reuleaux's method, §2),
:mod:`.wrenches` (contact forces, §3.1), :mod:`.support` (support friction, §3.2; its LPs
solved by the batched simplex of :mod:`.simplex`),
:mod:`.force_status` (P/U/I, §3.3-3.4), :mod:`.possible_motions` (the combined analysis, §4),
:mod:`.stable_pushing` (guaranteed-stable pushes and one-step goals, §4-5.1),
:mod:`.exact_region` (the exact stable pushes of an edge, containing STABLE's), :mod:`.regions`
(either method of an edge's stable pushes), :mod:`.stability_margin` (how far each push is from slipping),
:mod:`.contact_synthesis` (which edges realise a motion, §5.2), :mod:`.controllability`
(accessibility and STLC of a set of twists, 1996 §2), :mod:`.figures` (the paper's
figures redrawn). :mod:`.quasistatic` is an independent simulator that checks pushes without any
of the stable-region code.
"""

from .cones import Cone, cor_halfplanes
from .controllability import Controllability, controllability
from .contact_synthesis import EdgeRegions, edge_regions, stable_edges
from .contacts import ContactConfiguration
from .exact_region import DeadlineExceeded, ExactRegion, exact_region
from .force_status import Verdict, force_possible, force_status, force_status_regions, ray_twist
from .kinematics import (
    contact_modes,
    kinematic_cone,
    kinematic_cones,
    modes_of_motion,
    relative_cone,
    relative_mode,
)
from .possible_motions import ModeMotions, mode_possible, possible_motions
from .se2 import compose, exp_twist, inverse, log_pose, pose_error, relative_pose, transform_points, wrap_angle
from .slider import Slider
from .stability_margin import PushMargins, push_margins
from .regions import METHODS, PushRegion, stable_region
from .stable import DEFAULT_TIP_FACTOR, StableRegion, procedure_stable
from .stable_pushing import GOALS, classify_goal
from .steering import StableSteering
from .support import LoadBatch, SupportCells, SupportLoads, SupportModel, effective_cf, support_friction, unit_loads
from .twist import cor_to_twist, point_velocity, twist_to_cor
from .wrenches import contact_wrench_cone, friction_cone_edges, moment_labels, point_wrench

__all__ = [
    "Cone",
    "ContactConfiguration",
    "Controllability",
    "DEFAULT_TIP_FACTOR",
    "DeadlineExceeded",
    "EdgeRegions",
    "GOALS",
    "LoadBatch",
    "METHODS",
    "PushMargins",
    "PushRegion",
    "ModeMotions",
    "ExactRegion",
    "Slider",
    "StableRegion",
    "StableSteering",
    "SupportCells",
    "SupportLoads",
    "SupportModel",
    "Verdict",
    "classify_goal",
    "contact_modes",
    "contact_wrench_cone",
    "controllability",
    "cor_halfplanes",
    "cor_to_twist",
    "edge_regions",
    "effective_cf",
    "exact_region",
    "compose",
    "exp_twist",
    "inverse",
    "transform_points",
    "force_possible",
    "force_status",
    "force_status_regions",
    "friction_cone_edges",
    "kinematic_cone",
    "kinematic_cones",
    "log_pose",
    "pose_error",
    "mode_possible",
    "modes_of_motion",
    "moment_labels",
    "point_velocity",
    "point_wrench",
    "possible_motions",
    "procedure_stable",
    "push_margins",
    "ray_twist",
    "relative_cone",
    "relative_mode",
    "relative_pose",
    "stable_edges",
    "stable_region",
    "support_friction",
    "twist_to_cor",
    "unit_loads",
    "wrap_angle",
]
