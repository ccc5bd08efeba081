"""map_server maps: hand-made PGM/PNG images, every mode, threshold and negate, the origin, the
scenario's `static_map` key, and every bad-map case (one line naming file and field, exit 2)."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from anyplan.cli.main import main
from anyplan.errors import ScenarioError
from anyplan.world import load_scenario
from anyplan.world.occupancy import cell_values, load_map, read_image, read_pgm

ROBOT = ("robot: {start: [0.5, 0.5, 0], goal: [2.5, 0.5], radius: 0.2, v_max: 1, omega_max: 1, "
         "a_max: 1, alpha_max: 1}\n")


def write_pgm(path: Path, px: np.ndarray, maxval: int = 255, binary: bool = True,
              comment: bool = True) -> Path:
    h, w = px.shape
    head = b"P5" if binary else b"P2"
    hdr = head + (b"\n# made by a test\n" if comment else b"\n") + f"{w} {h}\n{maxval}\n".encode()
    if binary:
        body = px.astype(">u2" if maxval > 255 else "u1").tobytes()
    else:
        body = "\n".join(" ".join(str(int(v)) for v in row) for row in px).encode() + b"\n"
    path.write_bytes(hdr + body)
    return path


def write_png(path: Path, arr: np.ndarray, mode: str) -> Path:
    from PIL import Image

    Image.fromarray(arr.astype(np.uint8), mode=mode).save(path)
    return path


def write_yaml(path: Path, image: str, *, resolution: float = 0.5, origin=(0, 0, 0), negate=0,
               occ: float = 0.65, free: float = 0.196, mode: str | None = None,
               extra: str = "") -> Path:
    text = (f"image: {image}\nresolution: {resolution}\norigin: [{origin[0]}, {origin[1]}, "
            f"{origin[2]}]\nnegate: {negate}\noccupied_thresh: {occ}\nfree_thresh: {free}\n")
    if mode is not None:
        text += f"mode: {mode}\n"
    path.write_text(text + extra)
    return path


# A 2 x 3 image (top row first): shades chosen around the default thresholds.
#   p = (255 - v) / 255:  v=255 -> 0 (free), v=0 -> 1 (occupied), v=205 -> 0.196.. (unknown band)
IMG = np.array([[255, 0, 205],
                [254, 100, 230]])


@pytest.mark.parametrize("binary", [True, False])
def test_pgm_read_p5_and_p2(tmp_path, binary):
    f = write_pgm(tmp_path / "m.pgm", IMG, binary=binary)
    px, maxval = read_pgm(f)
    assert maxval == 255 and px.tolist() == IMG.tolist()


def test_pgm_16_bit_scaled_to_255(tmp_path):
    f = write_pgm(tmp_path / "m.pgm", np.array([[0, 65535, 32768]]), maxval=65535)
    shade, alpha = read_image(f)
    assert alpha is None
    assert np.allclose(shade, [[0.0, 255.0, 32768 * 255 / 65535]])


def test_trinary_thresholds_and_row_order(tmp_path):
    write_pgm(tmp_path / "m.pgm", IMG)
    m = load_map(write_yaml(tmp_path / "m.yaml", "m.pgm", occ=0.65, free=0.196))
    # row 0 of the map is the bottom image row
    # bottom row v = 254 (p=0.0039 free), 100 (p=0.608: unknown), 230 (p=0.098 free)
    # top row v = 255 free, 0 occupied, 205 (p=0.196.. >= 0.196: unknown)
    assert m.values.tolist() == [[0, -1, 0], [0, 100, -1]]
    assert m.blocked.tolist() == [[False, True, False], [False, True, True]]
    # moving the occupied threshold below p(100) = 0.608 makes that cell occupied
    m2 = load_map(write_yaml(tmp_path / "m2.yaml", "m.pgm", occ=0.6, free=0.196))
    assert m2.values[0, 1] == 100
    # raising free_thresh above p(205) = 0.196.. frees the top-right cell
    m3 = load_map(write_yaml(tmp_path / "m3.yaml", "m.pgm", occ=0.65, free=0.2))
    assert m3.values[1, 2] == 0 and not m3.blocked[1, 2]


def test_negate_flips_the_shade(tmp_path):
    write_pgm(tmp_path / "m.pgm", IMG)
    m = load_map(write_yaml(tmp_path / "m.yaml", "m.pgm", negate=1))
    # negated: v -> 255 - v, so p = v / 255: 255 -> occupied, 0 -> free
    assert m.values[1].tolist()[:2] == [100, 0]
    assert m.values[0, 0] == 100  # v = 254 -> p = 0.996


def test_scale_and_raw_modes():
    shade = np.array([[255.0, 0.0, 127.5, 50.0, 101.0]])
    sc = cell_values(shade, None, mode="scale", negate=False, occupied_thresh=0.65,
                     free_thresh=0.25)
    # p = 0, 1, 0.5, 0.804, 0.604: 0.5 -> 1 + 98 * (0.25 / 0.4) = 62.25 -> 62
    assert sc.tolist() == [[0, 100, 62, 100, 1 + round(98 * (1 - 101 / 255 - 0.25) / 0.4)]]
    alpha = np.array([[255.0, 255.0, 254.0, 255.0, 255.0]])
    sca = cell_values(shade, alpha, mode="scale", negate=False, occupied_thresh=0.65,
                      free_thresh=0.25)
    assert sca[0, 2] == -1  # not fully opaque and between the thresholds: unknown
    tri = cell_values(shade, alpha, mode="trinary", negate=False, occupied_thresh=0.65,
                      free_thresh=0.25)
    assert tri[0, 2] == -1 and tri[0, 4] == -1
    raw = cell_values(shade, None, mode="raw", negate=False, occupied_thresh=0.65,
                      free_thresh=0.25)
    assert raw.tolist() == [[-1, 0, -1, 50, -1]]


def test_raw_mode_blocks_by_free_thresh(tmp_path):
    write_pgm(tmp_path / "m.pgm", np.array([[0, 10, 30, 100, 200]]))
    m = load_map(write_yaml(tmp_path / "m.yaml", "m.pgm", mode="raw", free=0.25))
    assert m.values.tolist() == [[0, 10, 30, 100, -1]]
    assert m.blocked.tolist() == [[False, False, True, True, True]]


@pytest.mark.parametrize("mode", ["L", "LA", "RGB", "RGBA"])
def test_png_modes_match_pgm(tmp_path, mode):
    write_pgm(tmp_path / "m.pgm", IMG)
    ref = load_map(write_yaml(tmp_path / "ref.yaml", "m.pgm"))
    g = IMG.astype(np.uint8)
    arr = {"L": g, "LA": np.dstack([g, np.full_like(g, 255)]),
           "RGB": np.dstack([g, g, g]), "RGBA": np.dstack([g, g, g, np.full_like(g, 255)])}[mode]
    write_png(tmp_path / "m.png", arr, mode)
    m = load_map(write_yaml(tmp_path / "m.yaml", "m.png"))
    assert m.values.tolist() == ref.values.tolist()


def test_png_colour_is_averaged(tmp_path):
    arr = np.array([[[255, 255, 0], [0, 0, 30]]], dtype=np.uint8)  # means 170, 10
    write_png(tmp_path / "m.png", arr, "RGB")
    shade, _ = read_image(tmp_path / "m.png")
    assert shade.tolist() == [[170.0, 10.0]]


def test_origin_and_extent_define_the_arena(tmp_path):
    px = np.full((4, 6), 255)
    px[0, 5] = 0  # top-right pixel occupied
    write_pgm(tmp_path / "m.pgm", px)
    write_yaml(tmp_path / "m.yaml", "m.pgm", resolution=0.5, origin=(-1.0, 2.0, 0))
    sc_file = tmp_path / "s.yaml"
    sc_file.write_text("name: s\nstatic_map: m.yaml\nrobot: {start: [-0.5, 2.5, 0], goal: [1.5, 3.2], "
                       "radius: 0.2, v_max: 1, omega_max: 1, a_max: 1, alpha_max: 1}\n")
    sc = load_scenario(sc_file)
    assert sc.bounds == (-1.0, 2.0, 2.0, 4.0)
    obs = sc.obstacle_set()
    # the occupied cell is [1.5, 2] x [3.5, 4]
    assert obs.clearance((1.75, 3.75)) == 0.0
    assert obs.clearance((1.0, 3.2)) == pytest.approx(np.hypot(0.5, 0.3))
    assert obs.clearance((0.0, 3.0)) == pytest.approx(1.0)  # the wall x = -1 (and y = 2)
    assert sc.static_map.cell_of(1.75, 3.75) == (3, 5)
    d = sc.to_dict()
    assert Path(d["static_map"]).is_absolute()
    assert d["arena"]["origin"] == [-1.0, 2.0]


def test_static_map_combines_with_shapes_and_explicit_arena(tmp_path):
    write_pgm(tmp_path / "m.pgm", np.array([[255, 255, 255, 255], [0, 255, 255, 255]]))
    write_yaml(tmp_path / "m.yaml", "m.pgm", resolution=1.0)
    f = tmp_path / "s.yaml"
    f.write_text("name: s\nstatic_map: m.yaml\narena: {width: 5, height: 3, origin: [0, 0]}\n"
                 "static_obstacles: [{type: circle, center: [3.5, 2.5], radius: 0.2}]\n"
                 "robot: {start: [2.5, 0.5, 0], goal: [4.5, 0.5], radius: 0.2, v_max: 1, "
                 "omega_max: 1, a_max: 1, alpha_max: 1}\n")
    sc = load_scenario(f)
    obs = sc.obstacle_set()
    assert sc.bounds == (0.0, 0.0, 5.0, 3.0)
    assert obs.clearance((0.5, 0.5)) == 0.0        # the occupied map cell
    assert obs.clearance((3.5, 2.5)) == 0.0        # the circle
    assert obs.clearance((1.5, 0.5)) == pytest.approx(0.5)
    assert sc.nearest_static((1.4, 0.5)) == "map"
    assert sc.nearest_static((3.5, 2.0)) == "S1"
    # round trip through to_dict keeps the map and the content hash
    from anyplan.world import scenario_from_dict

    again = scenario_from_dict(sc.to_dict(), "<dict>")
    assert again.static_map == sc.static_map and again.content_hash() == sc.content_hash()


def _scenario(tmp_path: Path, map_text: str | None, img: np.ndarray | None = None,
              robot: str = ROBOT) -> Path:
    if img is not None:
        write_pgm(tmp_path / "m.pgm", img)
    if map_text is not None:
        (tmp_path / "m.yaml").write_text(map_text)
    f = tmp_path / "s.yaml"
    f.write_text("name: s\nstatic_map: m.yaml\n" + robot)
    return f


GOOD = ("image: m.pgm\nresolution: 1.0\norigin: [0, 0, 0]\nnegate: 0\noccupied_thresh: 0.65\n"
        "free_thresh: 0.196\n")
FREE = np.full((1, 3), 255)


@pytest.mark.parametrize(("map_text", "img", "where", "words"), [
    (None, FREE, "s.yaml: static_map", "no such map file"),
    (GOOD.replace("m.pgm", "nope.pgm"), FREE, "m.yaml: image", "no such file"),
    (GOOD.replace("resolution: 1.0", "resolution: -1"), FREE, "m.yaml: resolution", "must be > 0"),
    (GOOD.replace("[0, 0, 0]", "[0, 0, 0.3]"), FREE, "m.yaml: origin[2]", "not supported"),
    (GOOD.replace("[0, 0, 0]", "[0, 0]"), FREE, "m.yaml: origin", "expected [x, y, yaw]"),
    (GOOD.replace("free_thresh: 0.196", "free_thresh: 0.7"), FREE, "m.yaml: free_thresh",
     "must be < occupied_thresh"),
    (GOOD.replace("occupied_thresh: 0.65", "occupied_thresh: 1.5"), FREE,
     "m.yaml: occupied_thresh", "must be in [0, 1]"),
    (GOOD.replace("negate: 0", "negate: 2"), FREE, "m.yaml: negate", "expected 0 or 1"),
    (GOOD + "mode: trinery\n", FREE, "m.yaml: mode", "did you mean 'trinary'"),
    (GOOD + "colour: 1\n", FREE, "m.yaml: colour", "unknown key"),
    (GOOD.replace("negate: 0\n", ""), FREE, "m.yaml: negate", "missing required key"),
    (GOOD + "negate: 1\n", FREE, "m.yaml", "duplicate key"),
    (GOOD.replace("resolution: 1.0", "resolution: 1" + "0" * 400), FREE, "m.yaml: resolution",
     "number too large"),
    (GOOD.replace("[0, 0, 0]", "[100000, 0, 0]"), FREE, "m.yaml: origin[0]",
     "must be within +-10000 (the stated limit)"),
    (GOOD, np.array([[255, 255, 255], [0, 255, 255]]), "s.yaml: robot.start",
     "occupied or unknown cell"),
    (GOOD, np.array([[255, 255, 205]]), "s.yaml: robot.goal", "occupied or unknown cell"),
])
def test_bad_maps_exit_2_with_one_line(tmp_path, capsys, map_text, img, where, words):
    f = _scenario(tmp_path, map_text, img)
    with pytest.raises(ScenarioError):
        load_scenario(f)
    with pytest.raises(SystemExit) as ei:
        sys.exit(main(["plan", str(f), "--planner", "visgraph"]))
    assert ei.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("anyplan: error:")
    assert where in err and words in err, err


@pytest.mark.parametrize(("data", "words"), [
    (b"P5\n3 2\n255\n\x00\x00", "need 6"),                  # too few bytes for the size
    (b"P2\n3 2\n255\n0 0 0 0\n", "need 6"),
    (b"P2\n3 2\n255\n0 0 0 0 0 300\n", "outside 0..255"),
    (b"P5\n0 2\n255\n", "empty"),
    (b"P5\n3 x\n255\n", "bad PGM header"),
    (b"GIF89a...", "unsupported image format"),
])
def test_bad_images_name_the_image_field(tmp_path, capsys, data, words):
    (tmp_path / "m.pgm").write_bytes(data)
    f = _scenario(tmp_path, GOOD)
    with pytest.raises(SystemExit) as ei:
        sys.exit(main(["plan", str(f), "--planner", "visgraph"]))
    assert ei.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "m.yaml: image" in err and words in err, err


def test_arena_required_without_map(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text("name: s\n" + ROBOT)
    with pytest.raises(ScenarioError, match="arena: missing required key"):
        load_scenario(f)


# --------------------------------------------------------------------------------------------
# Values beyond the float range or the stated limits, huge pixels, image-size bombs, negate
# --------------------------------------------------------------------------------------------
BIG = "1" + "0" * 400  # an integer beyond the float range


def _load_error(path: Path) -> ScenarioError:
    with pytest.raises(ScenarioError) as ei:
        load_map(path)
    msg = str(ei.value)
    assert "\n" not in msg and msg.startswith(f"{path}: "), msg
    return ei.value


@pytest.mark.parametrize(("old", "new", "fld"), [
    ("resolution: 1.0", f"resolution: {BIG}", "resolution"),
    ("occupied_thresh: 0.65", f"occupied_thresh: {BIG}", "occupied_thresh"),
    ("free_thresh: 0.196", f"free_thresh: {BIG}", "free_thresh"),
    ("[0, 0, 0]", f"[{BIG}, 0, 0]", "origin[0]"),
    ("[0, 0, 0]", f"[0, -{BIG}, 0]", "origin[1]"),
])
def test_numbers_beyond_the_float_range_name_the_field(tmp_path, old, new, fld):
    write_pgm(tmp_path / "m.pgm", FREE)
    f = tmp_path / "m.yaml"
    f.write_text(GOOD.replace(old, new))
    exc = _load_error(f)
    assert exc.field == fld and "number too large" in str(exc), exc


@pytest.mark.parametrize(("origin", "fld"), [
    ("[100000, 0, 0]", "origin[0]"), ("[0, -10000.5, 0]", "origin[1]"),
    ("[1e17, 0, 0]", "origin[0]"), ("[1e300, 0, 0]", "origin[0]"),
])
def test_origin_beyond_the_coordinate_limit_is_refused(tmp_path, origin, fld):
    write_pgm(tmp_path / "m.pgm", FREE)
    f = tmp_path / "m.yaml"
    f.write_text(GOOD.replace("[0, 0, 0]", origin))
    exc = _load_error(f)
    assert exc.field == fld and "within +-10000 (the stated limit)" in str(exc), exc


def test_origin_limit_holds_with_an_explicit_arena(tmp_path):
    # the map 100 km away from a 4 x 2 m arena used to be accepted silently
    f = _scenario(tmp_path, GOOD.replace("[0, 0, 0]", "[100000, 0, 0]"), FREE)
    f.write_text(f.read_text().replace("static_map:", "arena: {width: 4, height: 2}\nstatic_map:"))
    with pytest.raises(ScenarioError, match=r"m\.yaml: origin\[0\]: must be within \+-10000"):
        load_scenario(f)


def test_a_map_wholly_outside_its_explicit_arena_is_refused(tmp_path):
    # within the coordinate limit but 5 km away from the 5 x 3 m arena: the map could hold
    # nothing the robot meets (a wrong origin), and was accepted in silence
    write_pgm(tmp_path / "m.pgm", np.array([[255, 255, 255, 255], [0, 255, 255, 255]]))
    write_yaml(tmp_path / "m.yaml", "m.pgm", resolution=1.0, origin=(5000.0, 0.0, 0.0))
    f = tmp_path / "s.yaml"
    f.write_text("name: s\nstatic_map: m.yaml\narena: {width: 5, height: 3, origin: [0, 0]}\n"
                 "robot: {start: [2.5, 0.5, 0], goal: [4.5, 0.5], radius: 0.2, v_max: 1, "
                 "omega_max: 1, a_max: 1, alpha_max: 1}\n")
    with pytest.raises(ScenarioError, match=r"static_map: the map \[5000, 5004\] x \[0, 2\] lies "
                                            r"outside the arena \[0, 5\] x \[0, 3\]") as info:
        load_scenario(f)
    assert "\n" not in str(info.value)
    # overlapping it by one cell is a map of part of the arena: accepted
    write_yaml(tmp_path / "m.yaml", "m.pgm", resolution=1.0, origin=(4.0, 2.0, 0.0))
    assert load_scenario(f).static_map is not None


@pytest.mark.parametrize(("res", "origin", "words"), [
    ("5000", "[0, 0, 0]", "far corner (15000, 5000) is beyond the coordinate limit"),  # 3 x 1 cells
    ("1e300", "[0, 0, 0]", "beyond the coordinate limit"),
    ("0.5", "[9999, -9999.5, 0]", "far corner (10000.5, -9999) is beyond"),
    ("1e-300", "[1, 0, 0]", "must be >= 1e-06 (the stated limit)"),  # cells too small to tell apart
])
def test_map_extent_and_resolution_limits_name_resolution(tmp_path, res, origin, words):
    write_pgm(tmp_path / "m.pgm", FREE)
    f = tmp_path / "m.yaml"
    f.write_text(GOOD.replace("resolution: 1.0", f"resolution: {res}").replace("[0, 0, 0]", origin))
    exc = _load_error(f)
    assert exc.field == "resolution" and words in str(exc), exc


def test_map_at_the_coordinate_limit_is_accepted(tmp_path):
    write_pgm(tmp_path / "m.pgm", FREE)
    f = tmp_path / "m.yaml"
    f.write_text(GOOD.replace("[0, 0, 0]", "[9997, -10000, 0]"))
    assert load_map(f).bounds == (9997.0, -10000.0, 10000.0, -9999.0)


@pytest.mark.parametrize("value", ["99999999999999999999999999", "-99999999999999999999999999"])
def test_p2_pixel_beyond_int64_is_refused_naming_the_image(tmp_path, value):
    (tmp_path / "m.pgm").write_bytes(f"P2\n2 2\n255\n1 2 3 {value}\n".encode())
    with pytest.raises(ValueError, match=r"pixel values outside 0\.\.255"):
        read_pgm(tmp_path / "m.pgm")
    f = tmp_path / "m.yaml"
    f.write_text(GOOD)
    exc = _load_error(f)
    assert exc.field == "image" and "m.pgm: pixel values outside 0..255" in str(exc), exc


def png_header(width: int, height: int) -> bytes:
    """A PNG of one 8-bit grey IHDR chunk (no pixel data) declaring ``width`` x ``height``."""
    import struct
    import zlib

    def chunk(kind: bytes, data: bytes) -> bytes:
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IEND", b"")


@pytest.mark.parametrize(("w", "h"), [(20000, 20000), (10000, 10000), (64001, 1000), (2**31 - 1, 2)])
def test_png_header_beyond_the_size_limit_is_refused_before_decoding(tmp_path, w, h):
    (tmp_path / "m.png").write_bytes(png_header(w, h))
    f = tmp_path / "m.yaml"
    f.write_text(GOOD.replace("m.pgm", "m.png"))
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        exc = _load_error(f)
    assert exc.field == "image" and f"image {w} x {h} has more than 64000000 pixels" in str(exc), exc
    assert not seen, [str(w.message) for w in seen]  # no DecompressionBombWarning


def test_png_bomb_header_exits_2_with_one_line(tmp_path, capsys):
    (tmp_path / "m.png").write_bytes(png_header(20000, 20000))
    f = _scenario(tmp_path, GOOD.replace("m.pgm", "m.png"))
    with pytest.raises(SystemExit) as ei:
        sys.exit(main(["plan", str(f), "--planner", "visgraph"]))
    assert ei.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "m.yaml: image:" in err and "more than 64000000" in err, err


@pytest.mark.parametrize("pillow_limit", [4, 2])
def test_pillow_size_limit_neither_warns_nor_raises_its_own_error(tmp_path, monkeypatch, pillow_limit):
    # 3 x 2 = 6 pixels: above 4 Pillow warns, above 2 x 2 it raises DecompressionBombError
    from PIL import Image

    write_png(tmp_path / "m.png", IMG, "L")
    monkeypatch.setattr(Image, "MAX_IMAGE_PIXELS", pillow_limit)
    f = write_yaml(tmp_path / "m.yaml", "m.png")
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        if pillow_limit == 4:
            assert load_map(f).shape == (2, 3)
        else:
            exc = _load_error(f)
            assert exc.field == "image" and "image 3 x 2 is beyond Pillow's size limit" in str(exc)
    assert not seen, [str(w.message) for w in seen]


def test_png_without_ihdr_first_is_refused(tmp_path):
    (tmp_path / "m.png").write_bytes(png_header(3, 2)[:16])  # cut inside the IHDR chunk
    f = tmp_path / "m.yaml"
    f.write_text(GOOD.replace("m.pgm", "m.png"))
    exc = _load_error(f)
    assert exc.field == "image" and "m.png: bad PNG header (no IHDR chunk" in str(exc), exc


@pytest.mark.parametrize(("text", "same_as"), [("true", 1), ("false", 0), ("yes", 1), ("off", 0)])
def test_negate_accepts_yaml_booleans_as_nav2_does(tmp_path, text, same_as):
    # Nav2's map_io reads negate as an int, else as a bool: a map Nav2 loads loads here too
    write_pgm(tmp_path / "m.pgm", IMG)
    ref = load_map(write_yaml(tmp_path / "ref.yaml", "m.pgm", negate=same_as))
    m = load_map(write_yaml(tmp_path / "m.yaml", "m.pgm", negate=text))
    assert m.negate is bool(same_as) and m.values.tolist() == ref.values.tolist()


@pytest.mark.parametrize("text", ["1.0", "0.0", "2", "-1", "'1'", "null"])
def test_negate_other_than_0_1_or_a_boolean_is_refused(tmp_path, text):
    write_pgm(tmp_path / "m.pgm", IMG)
    exc = _load_error(write_yaml(tmp_path / "m.yaml", "m.pgm", negate=text))
    assert exc.field == "negate" and "expected 0 or 1 (or true/false)" in str(exc), exc
