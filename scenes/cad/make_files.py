"""Write the CAD files of scenes/cad/bracket.yaml: bracket.dxf (by ezdxf) and jig.svg.

Run from anywhere: ``python scenes/cad/make_files.py`` (needs the cad extra). The files are
committed; this script says how they were made and remakes them.

bracket.dxf: on layer PART, a 70 x 40 mm plate whose two corners at +x are rounded (radius 10 mm,
LWPOLYLINE bulges) with a 12 mm bolt hole at (15, 5) mm; on layer NOTES, a title and a
construction line, which are not part of the part.
jig.svg: in millimetres (viewBox), a U-shaped jig whose pocket opens to the left (-x on the
table), its back a cubic Bezier; and a round post (a circle).
"""

from __future__ import annotations

import math
from pathlib import Path

import ezdxf

HERE = Path(__file__).resolve().parent
JIG = """\
<svg xmlns="http://www.w3.org/2000/svg" width="130mm" height="140mm" viewBox="0 -20 130 140">
  <!-- y points down the screen; the scene flips it, so the table shows what a viewer shows -->
  <path id="jig" d="M 0 0 L 100 0 C 125 30 125 70 100 100 L 0 100 L 0 75 L 85 75 L 85 25 L 0 25 Z"/>
  <circle id="post" cx="40" cy="-12" r="7"/>
  <text x="5" y="115">jig, mm</text>
</svg>
"""


def bracket(path: Path) -> None:
    w, h, r = 70.0, 40.0, 10.0
    bulge = math.tan(math.pi / 8)  # a quarter circle: the bulge is tan(angle / 4)
    doc = ezdxf.new(units=ezdxf.units.MM)
    msp = doc.modelspace()
    doc.layers.add("PART")
    doc.layers.add("NOTES")
    corners = [(-w / 2, -h / 2, 0), (w / 2 - r, -h / 2, bulge), (w / 2, -h / 2 + r, 0), (w / 2, h / 2 - r, bulge),
               (w / 2 - r, h / 2, 0), (-w / 2, h / 2, 0)]
    msp.add_lwpolyline(corners, format="xyb", close=True, dxfattribs={"layer": "PART"})
    msp.add_circle((15.0, 5.0), 6.0, dxfattribs={"layer": "PART"})
    msp.add_text("bracket, 3 mm steel", dxfattribs={"layer": "NOTES", "height": 3.0}).set_placement((-35.0, 25.0))
    msp.add_line((-40.0, 0.0), (40.0, 0.0), dxfattribs={"layer": "NOTES"})
    doc.saveas(path)


if __name__ == "__main__":
    bracket(HERE / "bracket.dxf")
    (HERE / "jig.svg").write_text(JIG)
