"""The exact regions against those of the previous construction, stored as test data.

``tests/data/exact_regions_v2.json`` holds, for every shipped scene's allowed edges (a part shared
by several scenes once) and the fixtures of ``test_exact_region.py`` and ``test_uncertainty.py``,
the section (push-plane polygon and centre) that ``exact_region`` returned with its default
parameters before its linear programmes were batched (planner.actions.region_cache ``_VERSION`` 2, one HiGHS
or Qhull call per twist and direction). Both constructions are sound on their own (the soundness
tests check the current one); this file checks that the faster one gave up no stable push: the
region is not smaller, and covers the old one polygon by polygon but for slivers where the two
certificates' multipliers differ (a degenerate LP has many optimal ones).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import shapely

from mechanics import Slider, exact_region

REFERENCE = json.loads((Path(__file__).resolve().parents[1] / "data" / "exact_regions_v2.json").read_text())


@pytest.mark.parametrize("case", REFERENCE["cases"], ids=[c["name"] for c in REFERENCE["cases"]])
def test_region_is_not_smaller_than_the_stored_one(case):
    slider = Slider(case["vertices"], cf=case["cf"])
    polygon, centre = exact_region(slider, case["edge"], case["mu"], case["width"], cf_radius=case["cf_radius"]).section()
    old = shapely.Polygon(case["polygon"])
    assert old.area > 0 and polygon.is_valid
    assert polygon.area >= 0.99 * old.area, polygon.area / old.area
    assert old.difference(polygon).area <= 0.005 * old.area
    # The trace starts from procedure STABLE's centroid, which did not change.
    np.testing.assert_allclose(centre, case["centre"], rtol=0, atol=1e-12)

