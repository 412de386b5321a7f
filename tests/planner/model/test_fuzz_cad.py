"""Property-based fuzzing of CAD files (issue 41): whatever a DXF, SVG or mesh file (STL, OBJ, PLY)
holds, a scene naming it either loads or raises one :class:`SceneError` whose message is one
short line naming a field, within a time bound; nothing is written, nothing printed (no warning,
no library's log line), and every note is one short printable line.

Files start from valid drawings written here (a plate with rounded corners and a bolt hole, block
references, curves; SVG shapes, groups and uses; meshes of two boxes and of a plate with a hole),
then are mutated: numbers replaced by hostile ones (NaN, infinities, 1e300, negative, not numbers,
ints past a float), entities repeated thousands of times, groups nested deep and ``<use>`` fanned
out, the file cut short, junk bytes spliced in. Each file is named by the part or an obstacle of a
scene, with its options drawn (units, chord, at, layer, object), and read by the command line's
input stage, :func:`planner.cli.read_inputs` (which loads it with :func:`planner.load_scene`). The
budget is an eighth of the Hypothesis profile's (``tests/conftest.py``): 100 examples a test in CI
(about 12 s for DXF, 6 for SVG, 1 for meshes here), 1,250 with ``--hypothesis-profile long`` (3.5
minutes).

Fuzzing found the joining of open DXF pieces by a union (:mod:`planner.model.cad.chains`), the
quadratic check of copied outlines, faces with holes needing networkx, and faces or vertices a mesh
does not have; each is a test in tests/planner/model/test_cad.py.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import struct
import time
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import yaml
from hypothesis import event, example, given, settings
from hypothesis import strategies as st

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")
trimesh = pytest.importorskip("trimesh")

from planner import load_scene  # noqa: E402 (after the skips)
from planner.cli import read_inputs  # noqa: E402
from planner.model.cad.dxf import NEEDS as DXF_NEEDS  # noqa: E402
from planner.model.cad.mesh import NEEDS as MESH_NEEDS  # noqa: E402
from planner.model.cad.svg import NEEDS as SVG_NEEDS  # noqa: E402
from planner.model.fields import SceneError  # noqa: E402
from test_cad import plate_with_a_hole  # noqa: E402
from test_fuzz_scenes import assert_one_line_naming_a_field, long_texts, root  # noqa: E402

#: An eighth of the profile's examples: each reads a CAD file, some of megabytes.
FEW = settings(max_examples=max(10, settings().max_examples // 8))
#: Seconds an example may take: the readers' caps keep the worst file to about two.
SLOWEST = 10.0
#: Loggers whose records are not printed (the readers give them a NullHandler).
QUIET = {name.split(".")[0] for name in (*DXF_NEEDS, *SVG_NEEDS, *MESH_NEEDS)}
#: Warnings Python does not print by default (outside __main__), so the command would not either.
UNSHOWN = (DeprecationWarning, PendingDeprecationWarning, ImportWarning, ResourceWarning)

# --- hostile pieces ----------------------------------------------------------------------------------

NUMBER_TEXTS = ["nan", "NaN", "inf", "-inf", "Infinity", "1e300", "-1e300", "1e999", "-1e999", "1e-320", "0", "-0",
                "-1", "1e16", "3.5e38", "abc", "", " ", "0x1F", "1_000", "1e", "--1", ".", "1.5.5", "9" * 400,
                str(10 ** 330), "4294967295", "-2147483649"]
number_texts = st.one_of(st.sampled_from(NUMBER_TEXTS), st.floats().map(repr), st.integers(-10**6, 10**6).map(str),
                         st.floats(-500, 500).map("{:.6g}".format))
JUNK = [b"\x00", b"\xff\xfe", b"\xef\xbb\xbf", b"\x1b[31m", b"\r", b"\n\n\n", b"<", b"]]>", b"&amp", b"\x80\x81",
        b"AutoCAD Binary DXF\r\n\x1a\x00", b"solid ", b"ply\n", b"o \n"]
junk = st.one_of(st.sampled_from(JUNK), st.binary(max_size=64))


@st.composite
def cut_or_spliced(draw: Callable, raw: bytes) -> bytes:
    """``raw`` cut short, with junk bytes spliced in, or as it is."""
    kind = draw(st.sampled_from(["as is", "as is", "cut", "junk"]))
    where = draw(st.integers(0, len(raw)))
    if kind == "cut":
        return raw[:where]
    if kind == "junk":
        return raw[:where] + draw(junk) + raw[where:]
    return raw


def text_of(write: Callable[[io.StringIO], None]) -> str:
    """What ``write`` writes to a text stream (an ezdxf document's ``write``)."""
    buffer = io.StringIO()
    write(buffer)
    return buffer.getvalue()


# --- DXF ---------------------------------------------------------------------------------------------

def plate(msp, layer: str = "PART", x: float = 0.0) -> None:
    """A 70 x 40 mm plate, two corners rounded by bulges, a bolt hole and a title."""
    bulge = math.tan(math.pi / 8)
    msp.add_lwpolyline([(x - 35, -20, 0), (x + 25, -20, bulge), (x + 35, -10, 0), (x + 35, 10, bulge), (x + 25, 20, 0),
                        (x - 35, 20, 0)], format="xyb", close=True, dxfattribs={"layer": layer})
    msp.add_circle((x + 15, 5), 6, dxfattribs={"layer": layer})
    msp.add_text("plate", dxfattribs={"layer": "NOTES"})


def dxf_plate() -> str:
    doc = ezdxf.new()
    plate(doc.modelspace())
    return text_of(doc.write)


def dxf_blocks() -> str:
    """A block of the plate, referenced from a block referenced twice from the model space."""
    doc = ezdxf.new()
    plate(doc.blocks.new("PLATE"), "0")
    outer = doc.blocks.new("TRAY")
    outer.add_blockref("PLATE", (0, 0))
    outer.add_blockref("PLATE", (0, 60))
    doc.modelspace().add_blockref("TRAY", (0, 0))
    doc.modelspace().add_blockref("TRAY", (100, 0), dxfattribs={"xscale": 2, "rotation": 30})
    return text_of(doc.write)


def dxf_curves() -> str:
    """An ellipse, a spline through points, an open spline of control points (not read: it does
    not close), a chain of lines and an arc that closes, and a polyline of two half circles."""
    doc = ezdxf.new()
    msp = doc.modelspace()
    msp.add_ellipse((0, 0), major_axis=(30, 0), ratio=0.4)
    msp.add_spline([(100, 0), (140, 0), (140, 40), (100, 40), (100, 0)])
    msp.add_open_spline([(200, 0), (240, 0), (240, 40), (200, 40)])
    msp.add_line((300, 0), (340, 0))
    msp.add_line((340, 0), (340, 20))
    msp.add_arc((320, 20), 20, 0, 180)
    msp.add_line((300, 20), (300, 0))
    msp.add_polyline2d([(400, 0, 0, 0, 1), (440, 0, 0, 0, 1)], format="xyseb", close=True)
    return text_of(doc.write)


DXF = {"plate": dxf_plate(), "blocks": dxf_blocks(), "curves": dxf_curves()}


def drawn_lines(lines: list[str]) -> int:
    """The index of the first line of the BLOCKS section (what the drawing draws comes after it)."""
    return lines.index("BLOCKS") if "BLOCKS" in lines else 0


@st.composite
def dxf_files(draw: Callable) -> bytes:
    """A valid drawing's text with one to three of: a number replaced, an entity's kind or a group
    code changed, an entity repeated up to 10,001 times; then perhaps cut short or spliced with junk."""
    lines = DXF[draw(st.sampled_from(sorted(DXF)), label="drawing")].splitlines()
    for _ in range(draw(st.integers(1, 3))):
        first = drawn_lines(lines)
        kind = draw(st.sampled_from(["number", "number", "number", "repeat", "code", "kind"]))
        starts = [k for k in range(first, len(lines) - 1, 2) if lines[k].strip() == "0"]  # each entity's first line
        if kind == "number":  # a value (odd line) that reads as a number
            numeric = [k for k in range(first + 1, len(lines), 2) if _is_number(lines[k])]
            if numeric:
                lines[draw(st.sampled_from(numeric))] = draw(number_texts)
        elif kind == "kind" and starts:  # the entity's kind: a DXF name, or one no program writes
            lines[draw(st.sampled_from(starts)) + 1] = draw(st.one_of(st.sampled_from(
                ["TEXT", "FOO", "INSERT", "SPLINE", "SEQEND", "ENDBLK", "\x1b[31mX", "X" * 500]), st.text(max_size=20)))
        elif kind == "code":  # a group code that is not one, or another one
            k = draw(st.integers(first // 2, len(lines) // 2 - 1)) * 2
            lines[k] = draw(st.sampled_from(["999", "-1", "abc", "", "10", "0", "1071", "330"]))
        elif kind == "repeat":  # an entity (from a "  0" line to the next) many times: thousands of entities
            if len(starts) > 1:
                k = draw(st.integers(0, len(starts) - 2))
                entity = lines[starts[k]:starts[k + 1]]
                lines[starts[k]:starts[k + 1]] = entity * draw(st.sampled_from([2, 50, 2000, 10_001]))
    return draw(cut_or_spliced("\n".join(lines).encode("utf-8", "surrogatepass")))


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


@st.composite
def dxf_block_nests(draw: Callable) -> bytes:
    """Blocks of references to the block below, ``fan`` each, ``depth`` deep, drawn from the top."""
    depth, fan = draw(st.integers(1, 12)), draw(st.integers(1, 12))
    doc = ezdxf.new()
    plate(doc.blocks.new("B0"), "0")
    for level in range(1, depth + 1):
        block = doc.blocks.new(f"B{level}")
        for k in range(fan):
            block.add_blockref(f"B{level - 1}", (100 * k, 0))
    doc.modelspace().add_blockref(f"B{depth}", (0, 0))
    return text_of(doc.write).encode()


# --- SVG ---------------------------------------------------------------------------------------------

plain = st.floats(0, 200).map("{:.4g}".format)
coordinates = st.one_of(plain, plain, plain, number_texts)  # mostly a drawing, sometimes not
IDS = ["a", "b", "c"]
TRANSFORMS = ["", "scale(1e300)", "scale(0)", "rotate(nan)", "matrix(0 0 0 0 0 0)", "translate(1e308 0)",
              "skewX(90)", "scale(-1 1)", "rotate(30 50 50)", "translate(10)", "scale(", "matrix(1 2)"]


@st.composite
def path_data(draw: Callable) -> str:
    """Path data of up to a dozen commands (moves, lines, curves, arcs, closes), any numbers."""
    parts = [f"M {draw(coordinates)} {draw(coordinates)}"] if draw(st.booleans()) else []
    for _ in range(draw(st.integers(0, 12))):
        command = draw(st.sampled_from("MLHVCSQTAZmlhvcsqtaz"))
        arity = {"M": 2, "L": 2, "H": 1, "V": 1, "C": 6, "S": 4, "Q": 4, "T": 2, "A": 7, "Z": 0}[command.upper()]
        parts.append(" ".join([command, *(draw(coordinates) for _ in range(arity))]))
    return " ".join(parts)


@st.composite
def element_attributes(draw: Callable) -> str:
    """An element's optional id (of a few, so that uses find them, and loops happen) and transform."""
    id_ = f' id="{draw(st.sampled_from(IDS))}"' if draw(st.booleans()) else ""
    transform = f' transform="{draw(st.sampled_from(TRANSFORMS))}"' if draw(st.integers(0, 3)) == 3 else ""
    return id_ + transform


#: The numbers each plain shape is drawn by.
SHAPES = {"rect": ("x", "y", "width", "height"), "circle": ("cx", "cy", "r"), "ellipse": ("cx", "cy", "rx", "ry"),
          "line": ("x1", "y1", "x2", "y2")}


@st.composite
def svg_shapes(draw: Callable) -> str:
    """One element of any kind drawn (a shape, a path, a polygon, a text, a use), any numbers."""
    kind = draw(st.sampled_from([*SHAPES, "path", "polygon", "text", "use"]))
    own = draw(element_attributes())
    if kind in SHAPES:
        numbers = " ".join(f'{key}="{draw(coordinates)}"' for key in SHAPES[kind])
        return f"<{kind} {numbers}{own}/>"
    if kind == "path":
        return f'<path d="{draw(path_data())}"{own}/>'
    if kind == "polygon":
        return f'<polygon points="{" ".join(draw(coordinates) for _ in range(draw(st.integers(0, 9))))}"{own}/>'
    if kind == "text":
        return f'<text x="{draw(coordinates)}" y="{draw(coordinates)}"{own}>label</text>'
    href = draw(st.sampled_from([*IDS, "missing", ""]))
    return f'<use {draw(st.sampled_from(["href", "xlink:href"]))}="#{href}" x="{draw(coordinates)}"{own}/>'


def group(children: list[str], own: str) -> str:
    return f"<g{own}>{''.join(children)}</g>"


@st.composite
def svg_elements(draw: Callable) -> str:
    """Shapes, and groups of them (each perhaps with an id, which uses refer to), nested."""
    tree = st.recursive(svg_shapes(), lambda inner: st.builds(group, st.lists(inner, max_size=5), element_attributes()),
                        max_leaves=16)
    return "".join(draw(st.lists(tree, min_size=1, max_size=5)))


VIEWBOXES = [' viewBox="0 0 200 200"', ' viewBox="0 0 200 200"', ' viewBox="0 0 0 0"', ' viewBox="nan nan 1 1"', ' viewBox="0 0 -5 10"', "",
             ' viewBox="0 0 200 200" width="100mm" height="100mm"', ' width="0" height="0"', ' width="1e300"']


@st.composite
def svg_grid(draw: Callable) -> str:
    """Up to eight shapes that a part could be (rect, circle, ellipse, a closed cubic path), one a
    cell of a grid 50 apart so that none crosses another, some with ids, some in a group: a
    drawing that reads, for the mutations below to break."""
    shapes = []
    for cell in draw(st.lists(st.integers(0, 15), min_size=1, max_size=8, unique=True)):
        x, y = 50 * (cell % 4) + 5, 50 * (cell // 4) + 5
        w, h = draw(st.floats(5, 40)), draw(st.floats(5, 40))
        own = f' id="{draw(st.sampled_from(IDS))}"' if draw(st.booleans()) else ""
        shapes.append(draw(st.sampled_from([
            f'<rect x="{x}" y="{y}" width="{w:.3f}" height="{h:.3f}"{own}/>',
            f'<circle cx="{x + 20}" cy="{y + 20}" r="{min(w, h) / 2:.3f}"{own}/>',
            f'<ellipse cx="{x + 20}" cy="{y + 20}" rx="{w / 2:.3f}" ry="{h / 2:.3f}"{own}/>',
            f'<path d="M {x} {y} L {x + w:.3f} {y} C {x + w + 5:.3f} {y + 5} {x + w + 5:.3f} {y + h:.3f} '
            f'{x + w:.3f} {y + h:.3f} L {x} {y + h:.3f} Z"{own}/>'])))
    split = draw(st.integers(0, len(shapes)))
    return "".join(shapes[:split]) + group(shapes[split:], ' id="c"')


@st.composite
def svg_files(draw: Callable) -> bytes:
    """A drawing of generated elements, or of a grid of shapes, perhaps with their deepest nesting,
    a fan of uses or thousands of copies added; then perhaps cut short or spliced with junk."""
    body = draw(st.one_of(svg_grid(), svg_elements()))
    extra = draw(st.sampled_from(["none", "none", "nest", "fan", "many", "entities"]))
    if extra == "nest":
        depth = draw(st.sampled_from([50, 99, 101, 1000, 5000]))
        body = "<g>" * depth + body + "</g>" * depth
    elif extra == "fan":  # groups of uses of the group below: fan ** depth copies
        fan, depth = draw(st.integers(2, 6)), draw(st.integers(2, 12))
        body += '<defs><g id="f0">' + body + "</g>" + "".join(
            f'<g id="f{k}">' + f'<use href="#f{k - 1}"/>' * fan + "</g>" for k in range(1, depth + 1)) + \
            f'</defs><use href="#f{depth}"/>'
    elif extra == "many":
        body *= draw(st.sampled_from([100, 3000, 10_001]))
    elif extra == "entities":  # the billion laughs, which expat refuses
        body += "&l9;"
    doctype = ('<!DOCTYPE svg [<!ENTITY l0 "ha">' + "".join(f'<!ENTITY l{k} "{f"&l{k - 1};" * 10}">'
                                                             for k in range(1, 10)) + "]>") if extra == "entities" else ""
    text = (f'{doctype}<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" '
            f'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"{draw(st.sampled_from(VIEWBOXES))}>'
            f'<g inkscape:groupmode="layer" inkscape:label="Parts">{body}</g></svg>')
    return draw(cut_or_spliced(text.encode()))


# --- meshes ------------------------------------------------------------------------------------------

def two_boxes() -> trimesh.Trimesh:
    """A 40 x 30 x 10 mm box on the table and a 10 mm cube 60 mm off, as one mesh."""
    return trimesh.util.concatenate([trimesh.creation.box((40, 30, 10)).apply_translation((0, 0, 5)),
                                     trimesh.creation.box((10, 10, 10)).apply_translation((60, 0, 5))])


#: The meshes the mutations start from: two boxes, and a plate whose top and bottom have a hole.
MESHES = {"boxes": two_boxes(), "plate": plate_with_a_hole(40, 10, 10, 5)}
floats32 = st.one_of(st.floats(width=32), st.sampled_from([0.0, -0.0, 1e38, -1e38, 3e38, 1e-45]), st.floats(-100, 100))


@st.composite
def stl_binary(draw: Callable) -> bytes:
    """A mesh as binary STL with some floats replaced, its triangle count changed, or both."""
    mesh = MESHES[draw(st.sampled_from(sorted(MESHES)))]
    raw = bytearray(mesh.export(file_type="stl"))
    for _ in range(draw(st.integers(0, 6))):
        k = draw(st.integers(0, len(mesh.faces) - 1)) * 50 + 84 + 4 * draw(st.integers(0, 11))
        raw[k:k + 4] = struct.pack("<f", draw(floats32))
    if draw(st.booleans()):
        raw[80:84] = struct.pack("<I", draw(st.sampled_from([0, 1, 2**32 - 1, 10**6, len(mesh.faces) + 1])))
    return draw(cut_or_spliced(bytes(raw)))


@st.composite
def mesh_texts(draw: Callable, text: str) -> bytes:
    """A mesh's text (ASCII STL, OBJ, ASCII PLY) with some numbers replaced or lines repeated."""
    lines = text.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        k = draw(st.integers(0, len(lines) - 1))
        words = lines[k].split()
        kind = draw(st.sampled_from(["number", "number", "repeat", "name"]))
        numeric = [j for j, word in enumerate(words) if _is_number(word.split("/")[0])]
        if kind == "number" and numeric:
            words[draw(st.sampled_from(numeric))] = draw(number_texts)
            lines[k] = " ".join(words)
        elif kind == "repeat":
            lines[k:k + 1] = [lines[k]] * draw(st.sampled_from([2, 1000, 200_001]))
        elif kind == "name":
            lines.insert(k, f"o {draw(st.one_of(st.sampled_from(['', 'a b', 'left', 'right']), st.text(max_size=9)))}")
    return draw(cut_or_spliced("\n".join(lines).encode("utf-8", "surrogatepass")))


def obj_text() -> str:
    """An OBJ of two objects: 'left', the plate with a hole, and 'right', a 10 mm cube 60 mm off."""
    lines, offset = [], 1
    right = trimesh.creation.box((10, 10, 10)).apply_translation((60, 0, 5))
    for name, mesh in (("left", MESHES["plate"]), ("right", right)):
        lines += [f"o {name}", *(f"v {x:g} {y:g} {z:g}" for x, y, z in mesh.vertices),
                  *(f"f {i + offset} {j + offset} {k + offset}" for i, j, k in mesh.faces)]
        offset += len(mesh.vertices)
    return "\n".join(lines) + "\n"


#: Each mesh in each text format, by suffix and mesh (the OBJ holds both, as objects).
MESH_TEXTS = {".stl": {name: mesh.export(file_type="stl_ascii") for name, mesh in MESHES.items()},
              ".ply": {name: mesh.export(file_type="ply", encoding="ascii").decode() for name, mesh in MESHES.items()},
              ".obj": {"objects": obj_text()}}


@st.composite
def mesh_files(draw: Callable) -> tuple[str, bytes]:
    suffix = draw(st.sampled_from([".stl", ".stl", ".obj", ".ply"]))
    if suffix == ".stl" and draw(st.booleans()):
        return suffix, draw(stl_binary())
    return suffix, draw(mesh_texts(MESH_TEXTS[suffix][draw(st.sampled_from(sorted(MESH_TEXTS[suffix])))]))


# --- the scene naming the file, and the property ------------------------------------------------------

#: The layers and objects of the drawings above, and names of neither.
LAYERS = {".dxf": ["PART", "part", "NOTES", "0"], ".svg": ["Parts"]}
OBJECTS = {".dxf": ["PLATE", "TRAY"], ".svg": IDS, ".stl": [], ".obj": ["left", "right"], ".ply": []}
OTHER_NAMES = st.one_of(st.sampled_from(["missing", "geometry_0", "*Model_Space", ""]), st.text(max_size=5), long_texts)


@st.composite
def references(draw: Callable, file: str) -> dict:
    """A file reference with its options drawn: mostly plain, sometimes hostile."""
    suffix = Path(file).suffix
    spec = {"file": file, "units": draw(st.sampled_from(["mm", "mm", "mm", "cm", "in", "m"]))}
    if draw(st.integers(0, 3)) == 3:  # Hypothesis favours small draws: the plain choice is 0
        spec["chord"] = draw(st.sampled_from([1e-6, 1e-5, 1e-3, 0.05, 1.0]))
    if draw(st.integers(0, 3)) == 3:
        spec["at"] = [draw(st.floats(-0.5, 0.5)), draw(st.floats(-0.5, 0.5)), draw(st.floats(-360, 360))]
    for key, names in (("layer", LAYERS.get(suffix, [])), ("object", OBJECTS[suffix])):
        if draw(st.integers(0, 3)) == 3:
            spec[key] = draw(st.sampled_from(names) if names and draw(st.integers(0, 3)) else OTHER_NAMES)
    return spec


@st.composite
def scenes(draw: Callable, file: str) -> dict:
    """A scene whose part is the file, or whose obstacle it is (a small box part far from it)."""
    base = {"pusher": {"width": 0.03, "depth": 0.01, "mu": 0.5}, "workspace": {"min": [-5, -5], "max": [5, 5]}}
    if draw(st.booleans()):
        return {**base, "slider": draw(references(file)), "start": [0, 0, 0], "goal": [0.5, 0, 90]}
    box = {"vertices": [[-0.04, -0.025], [0.04, -0.025], [0.04, 0.025], [-0.04, 0.025]]}
    return {**base, "slider": box, "obstacles": [draw(references(file))], "start": [4, 4, 0], "goal": [4, 3.5, 0]}


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """The working folder of every example: the scene and its CAD file, nothing else, before and after."""
    return tmp_path_factory.mktemp("fuzz-cad")


class _Records(logging.Handler):
    def __init__(self):
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)


@contextlib.contextmanager
def silent(where: Path) -> Iterator[None]:
    """Run in ``where`` and check that nothing is printed: no warning Python would show, no log
    record that would reach stderr (the readers' libraries' are dropped), nothing on stdout or stderr."""
    records, out = _Records(), io.StringIO()
    logging.getLogger().addHandler(records)
    try:
        with contextlib.chdir(where), warnings.catch_warnings(record=True) as caught, \
                contextlib.redirect_stdout(out), contextlib.redirect_stderr(out):
            warnings.simplefilter("always")
            yield
    finally:
        logging.getLogger().removeHandler(records)
    shown = [w for w in caught if not issubclass(w.category, UNSHOWN)]
    assert not shown, [str(w.message) for w in shown]
    printed = [r for r in records.records if r.name.split(".")[0] not in QUIET]
    assert not printed, [r.getMessage() for r in printed]
    assert out.getvalue() == ""


def check_file(folder: Path, name: str, content: bytes, scene: dict) -> None:
    """Read ``scene`` naming the CAD file ``name`` holding ``content`` as the command line does
    (:func:`read_inputs`, which loads it with :func:`planner.load_scene`): a scene whose notes are
    short lines, or one good error line, soon, and the folder left as it was."""
    for old in folder.iterdir():  # a failing example's, while Hypothesis shrinks
        old.unlink()
    (folder / name).write_bytes(content)
    (folder / "scene.yaml").write_text(yaml.safe_dump(scene))
    began = time.monotonic()
    with silent(folder):
        try:
            notes = read_inputs(["scene.yaml"]).scene.notes
            assert all(note.isprintable() and len(note) <= 300 for note in notes), notes
            event("accepted")
        except SceneError as err:
            assert_one_line_naming_a_field(err)
            event(f"refused: {root(err)}: {err.problem[:30]}")
    assert time.monotonic() - began < SLOWEST
    assert sorted(p.name for p in folder.iterdir()) == sorted({name, "scene.yaml"}), "reading must write nothing"


@FEW
@given(content=st.one_of(dxf_files(), dxf_block_nests()), data=st.data())
@example(content=DXF["plate"].encode(), data=None)
def test_hostile_dxf_files(folder, content, data):
    scene = data.draw(scenes("part.dxf")) if data else {
        "slider": {"file": "part.dxf", "units": "mm", "layer": "PART"}, "pusher": {"width": 0.03, "depth": 0.01, "mu": 0.5},
        "workspace": {"min": [-1, -1], "max": [1, 1]}, "start": [0, 0, 0], "goal": [0.5, 0, 0]}
    check_file(folder, "part.dxf", content, scene)


@FEW
@given(content=svg_files(), data=st.data())
def test_hostile_svg_files(folder, content, data):
    check_file(folder, "part.svg", content, data.draw(scenes("part.svg")))


@FEW
@given(case=mesh_files(), data=st.data())
def test_hostile_mesh_files(folder, case, data):
    suffix, content = case
    check_file(folder, f"part{suffix}", content, data.draw(scenes(f"part{suffix}")))


def test_the_valid_files_the_mutations_start_from_are_read(folder):
    """Each file the mutations start from is read as written, so that a refusal answers a mutation:
    the plate, alone on its layer or in its block; the curves, four outlines and an open spline;
    the plate with a hole (its outline 40 mm square) as STL, PLY and an OBJ's object; the two boxes,
    two parts."""
    plain = {"pusher": {"width": 0.03, "depth": 0.01, "mu": 0.5}, "workspace": {"min": [-5, -5], "max": [5, 5]},
             "start": [0, 0, 0], "goal": [0.5, 0, 90]}
    for name, text, options in [("part.dxf", DXF["plate"], {"layer": "PART"}),
                                ("part.dxf", DXF["blocks"], {"object": "PLATE"}),
                                ("part.obj", MESH_TEXTS[".obj"]["objects"], {"object": "left"}),
                                ("part.stl", MESH_TEXTS[".stl"]["plate"], {}),
                                ("part.ply", MESH_TEXTS[".ply"]["plate"], {})]:
        (folder / name).write_text(text)
        part = load_scene_in(folder, {**plain, "slider": {"file": name, "units": "mm", **options}}).slider
        rounded = (70 * 40 - 2 * (1 - math.pi / 4) * 10 ** 2) * 1e-6  # two corners of radius 10 mm
        assert part.area == pytest.approx(rounded if name == "part.dxf" else 40 * 40e-6, rel=1e-3), name
    (folder / "part.dxf").write_text(DXF["curves"])
    box = {"vertices": [[0, 0], [0.08, 0], [0.08, 0.05], [0, 0.05]]}
    loaded = load_scene_in(folder, {**plain, "slider": box, "obstacles": [{"file": "part.dxf", "units": "mm"}],
                                    "start": [4, 4, 0], "goal": [4, 3.5, 0]})
    assert len(loaded.obstacles) == 4
    assert loaded.notes == ("obstacles[0].file: 1 open chain(s) of lines or arcs do not close and are not read",)
    for suffix in (".stl", ".ply"):
        (folder / f"part{suffix}").write_text(MESH_TEXTS[suffix]["boxes"])
        with pytest.raises(SceneError, match="holds 2 parts: pick one with layer or object"):
            load_scene_in(folder, {**plain, "slider": {"file": f"part{suffix}", "units": "mm"}})


def load_scene_in(folder: Path, scene: dict):
    (folder / "scene.yaml").write_text(yaml.safe_dump(scene))
    with contextlib.chdir(folder):
        return load_scene("scene.yaml")
