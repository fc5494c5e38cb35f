#!/usr/bin/python3
"""tests/browser/run_browser_test.py: the library's GLSL in a real browser (headless Chromium on
SwiftShader's WebGL2), compared with the C++.

  preview  bakes a small folder with the built ibl-bake (--size 32 --quality low), serves the
           repository's tools/viewer/ and include/ibl/glsl/ and the folder on 127.0.0.1, lets
           tools/viewer/index.html?test=preview render ibl-bake's preview grid from specular.ktx2,
           dfg.hpp, lobe_lut.hpp and lobe_lut_b.hpp (the lobe model; --preset filament / gltf bake the
           split sum; --runtime taps2 the two-tap table, lobe_taps.hpp), sh.json and report.json, and compares its pixels with the bake's own
           preview.png (the C++ renderer, stage_preview.cpp) within the derived bound below. A bake
           with a block-compressed chain or irradiance map (--ktx2-format bc6h, astc4x4, astc6x6) is
           compared instead with the same grid rendered by `ibl-bake --lookup` (the C++ runtime
           shading the files as stored, decoded as a GPU decodes them; lookup_preview): preview.png
           is rendered from the float products, so it holds no compression error.
  screenshot  (not a test) bakes as `preview` does and saves Chromium's screenshot of the
           interactive viewer to --out (docs/shaders-viewer.png); with --page room, the room
           example (room.html) from --reference's JSON instead (docs/local_probes-room.png).
  prefilter  lets tools/viewer/prefilter.frag.glsl (include/ibl/glsl/ibl_prefilter.glsl) filter the
           fixtures' source (`glsl_reference --prefilter-fixtures`: the default sky at 64^2 split by
           the peak split, its base packed, and per LD weight and level the fast filter's taps and
           merged peaks, or the level's spherical-harmonic coefficients where the C++ default
           reconstructs it from them) and compares every texel of every convolved level with the C++ chain
           (ibl::prefilter, method fast, peaks.cut = 0) within half-float rounding: |GLSL - C++|
           <= 2^-11 |C++| per value. Then the viewer's own inputs (tools/viewer/refilter.js: the
           split, the base's packing, the taps, the peak lists, the band choice and projection, the
           projection also as a GPU pass: sh_project.frag.glsl) against the C++ ones, and the
           levels rendered from them against the C++ chain (1e-4 relative).
  refilter bakes the built-in sky with the fast filter into a float chain (--size N --prefilter
           fast --ktx2-format rgba32f; ctest: N = 64) and lets the viewer re-filter it live (Renderer.refilter,
           the viewer's button: refilter.js and ibl_prefilter.glsl from the chain's level 0); every
           re-filtered level against the chain ibl-bake wrote, within 2e-3 relative (the C++'s
           peak row cut is 1e-3).
  bc6h     the browser's own BC6H decoder against the library's: the page uploads the blocks that
           `bc6h_fixtures` prints (random blocks of every mode code, reserved ones included, and
           blocks ibl::bc6h_encode_image made of HDR content) as one EXT_texture_compression_bptc
           texture, reads every texel with texelFetch into an RGBA32F target, and every value must
           be exactly the library's half (bc6h_decode_block_half). Exit 77 (skipped) where the
           browser lacks EXT_texture_compression_bptc or EXT_color_buffer_float.
  room     lets tools/viewer/room.html draw the analytic room lit by two local probes (mirror and
           glossy walls; the left half the distant lookup, the right half parallax-corrected) from
           `room_reference`'s JSON (the scene, the probes' chains as halves, served as
           /bake/room_fixtures.json) and compares every pixel's linear RGB with the same pixels
           shaded by the library in C++ (room_reference.cpp), and the mirror pixels of both halves
           with the room's true radiance (the corrected half must be the nearer).
  numeric  lets tools/viewer/numeric.frag.glsl evaluate the GLSL functions on a fixed grid of
           inputs and compares them with the same grid evaluated by the library in C++
           (glsl_reference, tests/browser/glsl_reference.cpp); the page uploads the fixtures
           `glsl_reference --fixtures` prints (served as /bake/numeric_fixtures.json).

Everything this script starts (the bake, Chromium, the HTTP server thread) ends before it returns.
Exit status 0 = pass, 77 = skipped (the page says what the browser lacks). docs/shaders.md explains
the bounds.
"""

import argparse
import base64
import http.server
import json
import math
import os
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import zlib


# ---- PNG (8-bit RGB / RGBA, non-interlaced: what stb_image_write produces) ----------------------

def read_png_rgb(path):
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, w = 8, b"", None
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b"IHDR":
            w, h, depth, ctype, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or ctype not in (2, 6) or interlace:
                raise ValueError(f"{path}: only 8-bit RGB/RGBA non-interlaced PNGs are read")
            bpp = 3 if ctype == 2 else 4
        elif kind == b"IDAT":
            idat += body
        elif kind == b"IEND":
            break
    raw = zlib.decompress(idat)
    stride = w * bpp
    out = bytearray(h * stride)
    prev = bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pr = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pr) & 255
        out[y * stride:(y + 1) * stride] = line
        prev = line
    if bpp == 4:
        out = bytearray(v for i, v in enumerate(out) if i % 4 != 3)
    return w, h, bytes(out)


# ---- the page's server ------------------------------------------------------------------------------

class Server:
    """Serves /tools/viewer/, /include/ibl/glsl/, /include/ibl/bake/ (the fast filter's shape table
    the viewer re-filters with) from the repository and /bake/ from the bake folder; a POST to
    /result stores the page's JSON."""

    def __init__(self, repo, bake_dir):
        self.result = None
        self.done = threading.Event()
        outer = self
        roots = {"/tools/viewer/": os.path.join(repo, "tools", "viewer"),
                 "/include/ibl/glsl/": os.path.join(repo, "include", "ibl", "glsl"),
                 "/include/ibl/bake/": os.path.join(repo, "include", "ibl", "bake"),
                 "/bake/": bake_dir}

        class Handler(http.server.BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def _file(self):
                path = self.path.split("?")[0]
                for prefix, root in roots.items():
                    if path.startswith(prefix):
                        name = path[len(prefix):] or "index.html"
                        if "/" in name or name.startswith("."):
                            return None
                        full = os.path.join(root, name)
                        return full if os.path.isfile(full) else None
                return None

            def _send(self, head_only):
                full = self._file()
                if not full:
                    self.send_error(404)
                    return
                body = open(full, "rb").read()
                ctype = {".html": "text/html", ".js": "text/javascript", ".json": "application/json"}.get(
                    os.path.splitext(full)[1], "application/octet-stream")
                self.send_response(200)
                self.send_header("Content-Type", ctype)
                self.send_header("Content-Length", str(len(body)))
                self.send_header("Cache-Control", "no-store")
                self.end_headers()
                if not head_only:
                    self.wfile.write(body)

            def do_GET(self):
                self._send(False)

            def do_HEAD(self):
                self._send(True)

            def do_POST(self):
                n = int(self.headers.get("Content-Length", "0"))
                body = self.rfile.read(n)
                self.send_response(204)
                self.end_headers()
                if self.path.startswith("/result") and outer.result is None:
                    outer.result = json.loads(body)
                    outer.done.set()

        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = self.httpd.server_address[1]
        self.thread = threading.Thread(target=self.httpd.serve_forever, daemon=True)
        self.thread.start()

    def close(self):
        self.httpd.shutdown()
        self.httpd.server_close()
        self.thread.join()


SKIP = 77  # exit status of a test the browser cannot run (CTest SKIP_RETURN_CODE)


def run_page(chromium, url, profile, timeout, server):
    cmd = [chromium, "--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox",
           "--disable-gpu-sandbox", "--no-first-run", "--disable-background-networking", "--disable-component-update",
           "--disable-sync", "--disable-extensions", "--mute-audio", f"--user-data-dir={profile}",
           "--window-size=800,400", url]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, start_new_session=True)
    try:
        if not server.done.wait(timeout):
            raise RuntimeError(f"no result from the page within {timeout} s")
    finally:
        try:
            os.killpg(proc.pid, signal.SIGTERM)  # the browser's own process group (started above)
        except ProcessLookupError:
            pass
        try:
            proc.wait(10)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait()
        if proc.stderr:
            proc.stderr.close()
    if server.result.get("kind") == "error":
        raise RuntimeError("page error: " + server.result["error"])
    return server.result


# ---- preview comparison ------------------------------------------------------------------------------

CELL, COLS, ROWS = 128, 5, 2


def coverage_ambiguous(px, py, ss, margin):
    """True if a sub-pixel sample of pixel (px, py) lies within `margin` of a sphere's rim
    (|d2 - 1| < margin): float and double may classify it differently (sphere vs background)."""
    radius = 0.45 * CELL
    for sy in range(ss):
        for sx in range(ss):
            fx, fy = px + (sx + 0.5) / ss, py + (sy + 0.5) / ss
            ci, cj = min(int(fx) // CELL, COLS - 1), min(int(fy) // CELL, ROWS - 1)
            lx, ly = (fx - (ci + 0.5) * CELL) / radius, -(fy - (cj + 0.5) * CELL) / radius
            if abs(lx * lx + ly * ly - 1.0) < margin:
                return True
    return False


def preview_camera(light):
    """stage_preview.cpp make_camera: looking horizontally away from `light` (fwd, right, up)."""
    f = [-light[0], 0.0, -light[2]]
    l2 = f[0] * f[0] + f[2] * f[2]
    f = [f[0] / math.sqrt(l2), 0.0, f[2] / math.sqrt(l2)] if l2 > 1e-12 else [0.0, 0.0, -1.0]
    cross = lambda a, b: [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    r = cross(f, [0.0, 1.0, 0.0])
    n = math.sqrt(sum(c * c for c in r))
    r = [c / n for c in r]
    return f, r, cross(r, f)


def cap_ambiguous(px, py, ss, cam, sun, margin):
    """True if a background sub-sample of pixel (px, py) has its ray within `margin` of the sun
    disk's edge (|d.dir - cos r| < margin): float and double may disagree on inside vs outside.
    With the preview's camera (looking horizontally away from the brightest direction s, vertical
    half-field tan 0.4) d.s <= 0.4 s_y - |s_h| <= 0.4, while a sun (<= 0.01 sr) has cos r >= 0.998:
    the disk is never in view and no pixel is excluded; the check stays for other cameras."""
    if sun is None:
        return False
    fwd, right, up = cam
    direction, cos_r = sun
    radius = 0.45 * CELL
    w, h = COLS * CELL, ROWS * CELL
    tan_h = math.tan(0.5 * math.pi / 2)
    tan_v = tan_h * h / w
    for sy in range(ss):
        for sx in range(ss):
            fx, fy = px + (sx + 0.5) / ss, py + (sy + 0.5) / ss
            ci, cj = min(int(fx) // CELL, COLS - 1), min(int(fy) // CELL, ROWS - 1)
            lx, ly = (fx - (ci + 0.5) * CELL) / radius, -(fy - (cj + 0.5) * CELL) / radius
            if lx * lx + ly * ly < 1.0:
                continue  # a sphere
            nx, ny = 2.0 * fx / w - 1.0, 1.0 - 2.0 * fy / h
            d = [fwd[k] + nx * tan_h * right[k] + ny * tan_v * up[k] for k in range(3)]
            dn = math.sqrt(sum(c * c for c in d))
            if abs(sum(d[k] * direction[k] for k in range(3)) / dn - cos_r) < margin:
                return True
    return False


def max_slope_8bit():
    """max over x > 0 of d(255 sRGB(Reinhard(x))) / d ln x: the 8-bit change per unit relative
    change of the linear radiance (the derivation of the tolerance)."""
    best = 0.0
    for k in range(-4000, 4000):
        x = math.exp(k / 400.0)
        r = x / (1 + x)
        dr = r * (1 - r)  # dr / d ln x
        ds = 12.92 if r <= 0.0031308 else 1.055 / 2.4 * r ** (1 / 2.4 - 1)
        best = max(best, 255.0 * ds * dr)
    return best


def report_model(bake_dir):
    """The runtime model report.json names (plan.runtime.runtime_model.name)."""
    rt = json.load(open(os.path.join(bake_dir, "report.json")))["plan"]["runtime"]
    return rt.get("runtime_model", {}).get("name", "split-sum")


# The block-compressed formats (ktx2.js KTX2_FORMATS): the preview test compares them with the C++
# runtime shading the same compressed files (lookup_preview), not with preview.png.
BLOCK_FORMATS = {"BC6H_UFLOAT_BLOCK", "ASTC_4x4_SFLOAT_BLOCK", "ASTC_6x6_SFLOAT_BLOCK"}
PREVIEW_MATERIALS = [((0.8, 0.8, 0.8), 0.0), ((0.95, 0.64, 0.54), 1.0)]  # stage_preview's rows


def srgb_png(x, exposure):
    """image_png.cpp tonemap_png (Reinhard): a linear value -> its 8-bit sRGB code."""
    x *= exposure
    if not x > 0.0:
        return 0
    x = 1.0 if math.isinf(x) else x / (1.0 + x)
    y = (12.92 * x if x <= 0.0031308 else 1.055 * x ** (1.0 / 2.4) - 0.055) * 255.0 + 0.5
    return int(min(max(y, 0.0), 255.0))


def run_lookup(tool, folder, lines):
    """The answers of `ibl-bake --lookup folder` to the query lines, one list of floats each."""
    out = subprocess.run([tool, "--lookup", folder], input="\n".join(lines) + "\n", check=True, capture_output=True,
                         text=True).stdout.split("\n")
    bad = next((l for l in out if l.startswith("error")), None)
    if bad or len(out) < len(lines):
        raise RuntimeError("ibl-bake --lookup: " + (bad or f"{len(out)} answers to {len(lines)} queries"))
    return [[float(x) for x in out[i].split()] for i in range(len(lines))]


def lookup_preview(tool, bake_dir, ss, work):
    """The preview grid (stage_preview.cpp's camera, spheres, materials, sub-samples, exposure,
    Reinhard, sRGB, 8 bits) rendered by `ibl-bake --lookup`: the C++ runtime shading the bake's files
    as stored (the block formats decoded as a GPU decodes them). Spheres: `shade` (the runtime model,
    and lights.json's sun as a disk light). Background: `specular d 0` asked of a view of the folder
    without lights.json (so the answer is level 0 of the chain alone, bilinear, as the page's
    textureLod(chain, d, 0)), plus the sun's radiance where d is inside its cap (d.dir >= cos r,
    1 - cos r = omega / (2 pi); never in the preview's view). Returns RGB bytes, top row first."""
    report = json.load(open(os.path.join(bake_dir, "report.json")))
    if report["plan"]["runtime"].get("first_level", 0) != 0:
        raise RuntimeError("first_level > 0: the page's background (level 0) is not the lookup's roughness-0 LD")
    sunless = os.path.join(work, "sunless")
    os.makedirs(sunless)
    for name in os.listdir(bake_dir):
        if name != "lights.json":
            os.symlink(os.path.join(bake_dir, name), os.path.join(sunless, name))
    sun = None
    if os.path.exists(os.path.join(bake_dir, "lights.json")):
        suns = [l for l in json.load(open(os.path.join(bake_dir, "lights.json")))["lights"] if l.get("type") == "sun"]
        if suns:
            sun = (suns[0]["direction"], 1.0 - min(max(suns[0]["solid_angle"] / (2.0 * math.pi), 0.0), 1.0), suns[0]["radiance"])
    fwd, right, up = preview_camera(report["source"]["brightest_direction"])
    exposure = report["preview"]["exposure"]
    w, h = COLS * CELL, ROWS * CELL
    radius = 0.45 * CELL
    tan_h = math.tan(0.5 * math.pi / 2)
    tan_v = tan_h * h / w
    v = [-c for c in fwd]
    spheres, background, where = [], [], []  # where: per sub-sample (is sphere, index, sun radiance or None)
    for py in range(h):
        for px in range(w):
            for sy in range(ss):
                for sx in range(ss):
                    fx, fy = px + (sx + 0.5) / ss, py + (sy + 0.5) / ss
                    ci, cj = min(int(fx) // CELL, COLS - 1), min(int(fy) // CELL, ROWS - 1)
                    lx, ly = (fx - (ci + 0.5) * CELL) / radius, -(fy - (cj + 0.5) * CELL) / radius
                    d2 = lx * lx + ly * ly
                    if d2 < 1.0:  # orthographic sphere
                        z = math.sqrt(1.0 - d2)
                        n = [lx * right[k] + ly * up[k] - z * fwd[k] for k in range(3)]
                        base, metal = PREVIEW_MATERIALS[cj]
                        where.append((True, len(spheres), None))
                        spheres.append("shade %r %r %r %r %r %r %r %r %r %r %r" % (*n, *v, 0.25 * ci, metal, *base))
                    else:
                        nx, ny = 2.0 * fx / w - 1.0, 1.0 - 2.0 * fy / h
                        d = [fwd[k] + nx * tan_h * right[k] + ny * tan_v * up[k] for k in range(3)]
                        dn = math.sqrt(sum(c * c for c in d))
                        in_sun = sun and sum(d[k] / dn * sun[0][k] for k in range(3)) >= sun[1]
                        where.append((False, len(background), sun[2] if in_sun else None))
                        background.append("specular %r %r %r 0" % tuple(d))
    a_sphere = run_lookup(tool, bake_dir, spheres)
    a_background = run_lookup(tool, sunless, background)
    rgb = bytearray(3 * w * h)
    k, inv = 0, 1.0 / (ss * ss)
    for i in range(w * h):
        acc = [0.0, 0.0, 0.0]
        for _ in range(ss * ss):
            is_sphere, j, disk = where[k]
            k += 1
            a = a_sphere[j] if is_sphere else a_background[j]
            for c in range(3):
                acc[c] += a[c] + (disk[c] if disk else 0.0)
        for c in range(3):  # stage_preview stores the mean as float, image_png tone-maps it
            rgb[3 * i + c] = srgb_png(struct.unpack("<f", struct.pack("<f", acc[c] * inv))[0], exposure)
    return bytes(rgb)


def compare_preview(bake_dir, result, reference=None):
    """The page's pixels against preview.png, or against `reference` (lookup_preview's RGB bytes:
    the C++ shading of the stored, block-compressed files)."""
    w, h, ref = read_png_rgb(os.path.join(bake_dir, "preview.png"))
    got = base64.b64decode(result["rgb"])
    if reference is not None:  # what compression does to the picture (not a test: the float products' C++)
        float_ref = ref
        ref = reference
        dmax = max(abs(a - b) for a, b in zip(float_ref, ref))
        dmean = sum(abs(a - b) for a, b in zip(float_ref, ref)) / len(ref)
        print(f"reference: ibl-bake --lookup on the bake's stored files ({result['info']['chain_format']}); it differs from "
              f"preview.png (the float products) by max {dmax}, mean {dmean:.4f} (8-bit units, per channel)")
    if (w, h) != (result["width"], result["height"]) or len(got) != len(ref):
        raise RuntimeError(f"size mismatch: preview.png {w}x{h}, page {result['width']}x{result['height']}")
    info = result["info"]
    ss = info["preview_ss"]
    if "SwiftShader" not in info["renderer"]:
        raise RuntimeError(f"renderer {info['renderer']!r}: the bound below is derived for SwiftShader (float filtering)")
    # Relative error of the linear radiance between the two renderers (docs/shaders.md):
    #   chain: the default RGBA16F holds every texel within 2^-11 relative (round to nearest);
    #   LD is a convex (bilinear, linear blend, textbook) or geometric (L_l^(1-t) L_{l+1}^t)
    #   combination of texels, both of which keep a relative bound. RGBA32F is exact;
    #   B10G11R11 is within 2^-7 (R, G) and 2^-6 (B). E5B9G9R9's error is relative to the
    #   texel's largest channel: no per-channel relative bound, so no test bound.
    #   DFG table: dfg.hpp's exact floats in an RGBA32F texture: no storage error.
    #   Arithmetic: float (GPU) vs double (the C++ shading, float lookups): < 1e-5 relative.
    #   Filtering: SwiftShader computes bilinear weights in float. A GPU that quantises them
    #   (Vulkan guarantees only subTexelPrecisionBits >= 4) errs by a fraction of the difference
    #   of neighbouring texels, which no relative bound covers: the bound holds for SwiftShader.
    chain_eps = {"R16G16B16A16_SFLOAT": 2.0 ** -11, "R32G32B32A32_SFLOAT": 0.0, "B10G11R11_UFLOAT_PACK32": 2.0 ** -6}
    #   Block formats (BC6H, ASTC HDR): compared with the C++ shading the same compressed files
    #   (lookup_preview), both sides read the same decoded halves: no storage error. That the
    #   browser's BC6H decoder returns the library's halves bit for bit is glsl_browser_bc6h's
    #   check; ASTC HDR is assumed to decode as astcenc does (no browser here offers it).
    if reference is not None:
        chain_eps.update({f: 0.0 for f in BLOCK_FORMATS})
    # The irradiance map (plan.runtime.diffuse "irradiance_map") is stored in the same formats and
    # read by one bilinear lookup: the same relative bound per texel format.
    formats = [info["chain_format"]]
    if info["runtime"]["diffuse"] == "irradiance_map":
        formats.append(info["irradiance_format"])
    for f in formats:
        if f not in chain_eps:
            raise RuntimeError(f"no bound derived for a {f} texture")
    if info["lut_texture"] != "RGBA32F":
        raise RuntimeError("the DFG table is not an RGBA32F texture (no OES_texture_float_linear): no bound derived")
    # The lobe model (report.json runtime_model "lobe"): lobe_lut.hpp's exact floats in an RGBA32F
    # texture (no storage error); its lookup direction normalize(lerp(n, R, s)) and r_eff are formed
    # in float on both sides (the C++ reads the table and the chain in float too): inside the
    # arithmetic term below.
    expected_model = report_model(bake_dir)
    if info.get("runtime_model") != expected_model:
        raise RuntimeError(f"the page shaded with {info.get('runtime_model')!r}, the bake's model is {expected_model!r}")
    if expected_model == "lobe" and info.get("lobe_texture") != "RGBA32F":
        raise RuntimeError("the lobe LUT is not an RGBA32F texture: no bound derived")
    # The two-part lobe model (runtime_model.parts = 2): lobe_lut_b.hpp's floats as a second RGBA32F
    # texture; its LD (F0 A LD_a + F90 B LD_b) / (F0 A + F90 B) is a convex combination of two chain
    # reads, which keeps the chain's relative bound.
    if expected_model == "lobe":
        parts = json.load(open(os.path.join(bake_dir, "report.json")))["plan"]["runtime"]["runtime_model"].get("parts", 1)
        if info.get("lobe_parts") != parts:
            raise RuntimeError(f"the page shaded the lobe model with {info.get('lobe_parts')} part(s), the bake has {parts}")
    # The two-tap model (runtime_model "taps2"): lobe_taps.hpp's exact floats in two RGBA32F
    # textures; the taps' directions cos(a) n + sin(a) t are formed in float on both sides and LD
    # is their weighted mean, a convex combination of chain reads that keeps the chain's relative
    # bound: inside the terms below.
    if expected_model == "taps2" and info.get("taps_texture") != "RGBA32F":
        raise RuntimeError("the two-tap table is not an RGBA32F texture: no bound derived")
    eps = max(chain_eps[f] for f in formats) + 1e-5
    # The sun (lights.json) as a disk light: its specular D(n.h; alpha') turns an error dc of n.h
    # into a relative error <= 4 dc / alpha'^2 (at the lobe's peak, c = 1), alpha'^2 >= tan^2(r/2)
    # (roughness 0, v.h <= 1); n, v and h are unit vectors formed in float on the GPU: dc <= 2^-21
    # (8 ulp of 1). The background's disk is never in view (below), so it adds nothing.
    sun_eps = 0.0
    if info.get("sun"):
        c1 = min(max(info["sun"]["solidAngle"] / (2.0 * math.pi), 0.0), 1.0)
        sun_eps = 4.0 * 2.0 ** -21 / (c1 / (2.0 - c1))
        eps += sun_eps
    slope = max_slope_8bit()
    # Both sides round the same function to 8 bits: if the unrounded values differ by less than
    # delta = slope * eps (in 8-bit units), the rounded ones differ by at most floor(delta) + 1.
    delta = slope * eps
    bound = math.floor(delta) + 1
    # The sun (lights.json) is drawn in the background where d.dir >= cos r, 1 - cos r = omega / (2 pi).
    sun = None
    if info.get("sun"):
        s = info["sun"]
        sun = (s["direction"], 1.0 - min(max(s["solidAngle"] / (2.0 * math.pi), 0.0), 1.0))
    report = json.load(open(os.path.join(bake_dir, "report.json")))
    cam = preview_camera(report["source"]["brightest_direction"])
    diffs, amb, amb_cap, hist = [], 0, 0, {}
    worst = (0, 0, 0)
    for y in range(h):
        for x in range(w):
            if coverage_ambiguous(x, y, ss, 1e-5):
                amb += 1
                continue
            if cap_ambiguous(x, y, ss, cam, sun, 1e-5):
                amb_cap += 1
                continue
            i = 3 * (y * w + x)
            d = max(abs(got[i + c] - ref[i + c]) for c in range(3))
            diffs.append(sum(abs(got[i + c] - ref[i + c]) for c in range(3)) / 3.0)
            hist[d] = hist.get(d, 0) + 1
            if d > worst[0]:
                worst = (d, x, y)
    total = sum(diffs) / len(diffs)
    print(f"renderer: {info['renderer']}")
    print(f"diffuse {info['runtime']['diffuse']}" + (f" ({info['irradiance_format']})" if len(formats) > 1 else ""))
    print(f"chain {info['chain_format']} levels {info['chain_levels']}, DFG texture {info['lut_texture']} "
          f"{info['lut_size']}^2, exposure {info['exposure']:.8g}, {ss}x{ss} samples per pixel")
    print(f"runtime model {info['runtime_model']}" +
          (f" (lobe LUT {info['lobe_texture']} {info['lobe_size']}^2, {info['lobe_parts']} part(s))" if info['runtime_model'] == "lobe" else "") +
          (f" (two-tap table 2 x {info['taps_texture']} {info['taps_size']}^2)" if info['runtime_model'] == "taps2" else ""))
    print(f"sun: " + (f"omega {info['sun']['solidAngle']:.6g} sr, specular term's eps {sun_eps:.3g}" if info.get("sun") else "none"))
    print(f"derived: eps = {eps:.3g} relative, max 8-bit slope {slope:.2f} per unit ln L, delta {delta:.3f} "
          f"-> bound {bound} (8-bit units)")
    print(f"pixels compared {len(diffs)} (excluded {amb} whose samples lie within 1e-5 of a sphere rim, "
          f"{amb_cap} whose background rays lie within 1e-5 of the sun disk's edge in d.dir)")
    print(f"max |diff| {worst[0]} at ({worst[1]}, {worst[2]}), mean |diff| {total:.4f} (8-bit units, per channel)")
    print("histogram of max channel |diff|: " + ", ".join(f"{k}: {hist[k]}" for k in sorted(hist)))
    ok = worst[0] <= bound
    print("PASS" if ok else f"FAIL: max |diff| {worst[0]} > bound {bound}")
    return ok


# ---- numeric comparison ------------------------------------------------------------------------------

def compare_numeric(reference_exe, result):
    ref = json.loads(subprocess.run([reference_exe], check=True, capture_output=True, text=True).stdout)
    w, h = result["width"], result["height"]
    vals = result["values"]  # rows from the bottom (readPixels), RGBA
    if (w, h) != (ref["width"], ref["height"]):
        raise RuntimeError("grid size mismatch")
    ok, worst = True, {}
    for row in ref["rows"]:
        j, name, tol_rel, tol_abs = row["row"], row["name"], row["rel"], row["abs"]
        wmax = 0.0
        for i, expect in enumerate(row["values"]):
            got = vals[4 * (j * w + i):4 * (j * w + i) + 4]
            for c in range(4):
                e, g = expect[c], got[c]
                err = abs(g - e)
                # "abs_values": a per-value absolute bound in place of the row's (glsl_reference.cpp)
                lim = (row["abs_values"][i][c] if "abs_values" in row else tol_abs) + tol_rel * abs(e)
                wmax = max(wmax, err / lim if lim > 0 else err)
                if not err <= lim:
                    if ok or worst.get(name, 0) < 3:
                        print(f"  {name}[{i}].{c}: GLSL {g!r} C++ {e!r} |diff| {err:.3g} > {lim:.3g}")
                    worst[name] = worst.get(name, 0) + 1
                    ok = False
        abs_text = "per-value abs" if "abs_values" in row else f"{tol_abs:g}"
        print(f"{name:28s} {len(row['values'])} cases x 4: worst |diff| / bound {wmax:.3g} "
              f"(bound {abs_text} + {tol_rel:g} |C++|)")
        if "probe_dt" in row:  # the texture unit's effective filter-weight error: |diff| / |texel difference|
            ratios = [abs(vals[4 * (j * w + i) + c] - e[c]) / abs(dt[c])
                      for i, (e, dt) in enumerate(zip(row["values"], row["probe_dt"])) for c in range(3)
                      if abs(dt[c]) >= 1.0 / 16.0]
            print(f"{'':28s} filter weight error max |diff| / |texel difference| {max(ratios):.3g} "
                  f"over {len(ratios)} values with |difference| >= 1/16")
    print(f"renderer: {result.get('renderer')}")
    print("PASS" if ok else "FAIL")
    return ok


def compare_prefilter(fixtures, result):
    ok = True
    by_level = {(lv["level"], lv["weight"]): lv for lv in result["levels"]}
    for lv in fixtures["levels"]:
        got = by_level.get((lv["level"], lv["weight"]))
        expect = lv["expect"]
        name = f"level {lv['level']} ({lv['weight']})"
        if got is None or len(got["rgb"]) != len(expect):
            print(f"{name}: missing or wrong size")
            ok = False
            continue
        worst, bad = 0.0, 0
        for i, (e, g) in enumerate(zip(expect, got["rgb"])):
            lim = 2.0 ** -11 * abs(e)
            ratio = abs(g - e) / lim if lim > 0 else abs(g - e)
            worst = max(worst, ratio)
            if not abs(g - e) <= lim:
                if bad < 3:
                    print(f"  {name} value {i}: GLSL {g!r} C++ {e!r}")
                bad += 1
        tail = f", coarse tail {lv['tail_share']:.4g} of the {lv['next_n']}^2 next level" if lv.get("tail_share", 0) > 0 else ""
        if "mid" in lv:
            m = lv["mid"]
            tail = (f", coarse tail {lv['tail_share']:.4g} of an intermediate {m['n']}^2 level at r = {m['roughness']:.4g} "
                    f"({m['count']} taps, its own tail {m['tail_share']:.4g} of the next level)")
        how = f"{lv['sh_bands']} SH bands" if lv.get("sh_bands", 0) > 0 else f"{lv['count']} taps"
        print(f"{name} ({lv['n']}^2 x 6, {how}, {lv['peak_count']} peaks{tail}): worst |diff| / (2^-11 |C++|) "
              f"{worst:.3g}, {bad} values outside")
        ok = ok and bad == 0
    # The viewer's live path (tools/viewer/refilter.js): its packing and taps against the C++ ones,
    # and its render against the C++ chain (the taps' lods and weights agree to float rounding,
    # so within 1e-4 relative).
    # The peak split (refilter.js splitPeaks, packSource with peaks, makePeakLevel) against the C++'s
    # (split_cube_peaks, pack_cube of the base, make_peak_level): the same peaks, directions to float
    # rounding, energies to 1e-5 relative (the threshold's mean is summed in another order).
    print(f"viewer split: {result['source_peaks']} level-0 peaks (C++ {fixtures['source_peaks']}), threshold "
          f"{result['threshold']:.9g} (C++ {fixtures['threshold']:.9g})")
    ok = ok and result["source_peaks"] == fixtures["source_peaks"]
    ok = ok and abs(result["threshold"] - fixtures["threshold"]) <= 1e-6 * fixtures["threshold"]
    # The packing relative to max(|base texel|, |source texel|): the C++ takes a peak out of its float
    # mips of the source, so a patched texel keeps the rounding of the source's (up to the sun's).
    print(f"viewer packing: max difference from ibl::detail::pack_cube {result['packed_max_rel']:.3g} of the larger "
          f"of the base's and the source's texel ({result['packed_max_rel_base']:.3g} of the base's)")
    ok = ok and result["packed_max_rel"] <= 1e-6
    def taps_ok(d):
        # the taps to float rounding, the factor and the coarse tail's share (0 without one)
        return "max_abs" in d and d["max_abs"] <= 1e-5 and abs(d["factor"] - d["expected_factor"]) <= 1e-6 * abs(d["expected_factor"]) \
            and abs(d.get("tail_share", -1) - d.get("expected_tail_share", 0)) <= 1e-6
    for lv, d in zip(fixtures["levels"], result["taps"]):
        print(f"viewer taps, level {lv['level']} ({lv['weight']}): {d}")
        ok = ok and taps_ok(d) and (("mid" in lv) == ("mid" in d)) and ("mid" not in lv or taps_ok(d["mid"]))
    # The intermediate coarse tail's rule (refilter.js midTail against prefilter_mid_roughness and
    # the own and intermediate samples): the same levels, roughness and samples.
    for lv, d in zip(fixtures["levels"], result["mid"]):
        print(f"viewer intermediate level, level {lv['level']} ({lv['weight']}): {d}")
        ok = ok and d["mid"] == d["expected_mid"]
        if d["expected_mid"]:
            ok = ok and d["roughness_abs"] <= 1e-12 and d["own"] == d["expected_own"] and d["samples"] == d["expected_samples"]
    ok = ok and any("mid" in lv for lv in fixtures["levels"])  # the fixtures force one
    for lv, d in zip(fixtures["levels"], result["peaks"]):
        print(f"viewer peaks, level {lv['level']} ({lv['weight']}): {d} (C++ {lv['peak_count']} peaks)")
        ok = ok and d.get("count") == lv["peak_count"] and "dir_max_abs" in d and d["dir_max_abs"] <= 1e-6 and \
            d["energy_max_rel"] <= 1e-5 and abs(d["a2"] - d["expected_a2"]) <= 1e-7 * d["expected_a2"]
    # The levels by spherical harmonics (refilter.js shBands, shProject, shLevel) against the C++'s
    # (sh_rough_bands, sh_projection in float lanes, sh_level::set_coefficients): the same bands and
    # projected face, coefficients within 1e-5 of their row's largest, the recurrence's constants
    # to float rounding.
    for lv, d in zip(fixtures["levels"], result["sh"]):
        print(f"viewer sh, level {lv['level']} ({lv['weight']}): {d}")
        ok = ok and d.get("bands") == lv["sh_bands"]
        if lv["sh_bands"] > 0:
            ok = ok and d.get("face") == lv["projection_face"] and d.get("cosine_max_rel", 1) <= 1e-5 and \
                d.get("sine_max_rel", 1) <= 1e-5 and d.get("recurrence_max_rel", 1) <= 1e-7
    # The same projection on the GPU (sh_project.frag.glsl, ibl_prefilter_sh_project: float sums in
    # row order) made into the levels' textures: the same bounds.
    for lv, d in zip(fixtures["levels"], result["sh_gpu"]):
        print(f"GPU sh projection, level {lv['level']} ({lv['weight']}): {d}")
        if lv["sh_bands"] > 0:
            ok = ok and d.get("bands") == lv["sh_bands"] and d.get("face") == lv["projection_face"] and \
                d.get("cosine_max_rel", 1) <= 1e-5 and d.get("sine_max_rel", 1) <= 1e-5
    by_level = {(lv["level"], lv["weight"]): lv for lv in result["js_levels"]}
    for lv in fixtures["levels"]:
        got = by_level.get((lv["level"], lv["weight"]))
        worst = max(abs(g - e) / max(abs(e), 1e-30) for e, g in zip(lv["expect"], got["rgb"])) if got else float("inf")
        print(f"viewer re-filter, level {lv['level']} ({lv['weight']}): worst relative difference from ibl::prefilter {worst:.3g}")
        ok = ok and worst <= 1e-4
    print(f"renderer: {result.get('renderer')}")
    print("PASS" if ok else "FAIL")
    return ok


def compare_refilter(result, intermediate=0, rel=2e-3):
    """The viewer's live re-filter (Renderer.refilter: refilter.js and ibl_prefilter.glsl on the
    chain's level 0) against the chain ibl-bake wrote (ibl::prefilter, the fast filter): every value
    within `rel` of the C++'s, relative to max(|C++|, 1e-3 of the level's mean). The differences
    are the peak split's row cut (prefilter peaks.cut = 1e-3: the C++ skips the peaks that change no
    texel of a row by more than 1e-3 relative; the GPU adds every peak) and float rounding."""
    ok = bool(result["levels"])
    t = result["timing"]
    print(f"re-filter: {t['levels']} levels ({t.get('intermediate', 0)} intermediate levels drawn too, the bake's report "
          f"names {intermediate}), {t['peaks']} peaks: {t['gpu_ms']:.1f} ms GPU + {t['prepare_ms']:.1f} ms CPU")
    # the viewer's rule (refilter.js midTail) finds the bake's intermediate levels (report.json's
    # specular.mid_tail.mid_roughness_per_level)
    ok = ok and t.get("intermediate", 0) == intermediate
    for lv in result["levels"]:
        cpp, gpu = lv["cpp"], lv["gpu"]
        mean = sum(abs(v) for v in cpp) / max(1, len(cpp))
        floor = 1e-3 * mean
        worst, sq, bad = 0.0, 0.0, 0
        for e, g in zip(cpp, gpu):
            d = abs(g - e) / max(abs(e), floor)
            worst = max(worst, d)
            sq += d * d
            bad += 0 if d <= rel else 1
        rms = (sq / max(1, len(cpp))) ** 0.5
        print(f"level {lv['level']} ({lv['n']}^2 x 6): worst relative difference {worst:.3g}, rms {rms:.3g}, {bad} values above {rel:g}")
        ok = ok and len(cpp) == len(gpu) == 18 * lv["n"] ** 2 and bad == 0
    print(f"renderer: {result.get('renderer')}")
    print("PASS" if ok else "FAIL")
    return ok


# ---- room comparison ------------------------------------------------------------------------------

def luminance(rgb):
    return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]


# The room test's bound: half-float rounding of the value (2^-11 relative) plus 2^-14 absolute; the
# arithmetic and filtering differences measured on SwiftShader use 0.07 of it (docs/local_probes.md).
ROOM_REL, ROOM_ABS = 2.0 ** -11, 2.0 ** -14


def compare_room(fixtures, result, rel, absolute):
    """Every pixel's linear RGB (rows from the bottom, both halves) against room_reference's, within
    rel |C++| + absolute; the same pixels tone-mapped to 8 bits (Reinhard, sRGB) within one code;
    and the mirror pixels against the room's true radiance: the corrected half's relative RMSE of
    luminance must be below a quarter of the distant lookup's."""
    w, h = fixtures["width"], fixtures["height"]
    if (result["width"], result["height"]) != (w, h):
        raise RuntimeError(f"the page drew {result['width']} x {result['height']}, expected {w} x {h}")
    vals, expect = result["values"], fixtures["expect"]
    excluded = set(fixtures["excluded"])
    worst, worst_at, bad, worst8, compared = 0.0, None, 0, 0, 0
    hist = {}
    for i in range(w * h):
        if i in excluded:
            continue
        compared += 1
        d8 = 0
        for c in range(3):
            e, g = expect[3 * i + c], vals[4 * i + c]
            lim = rel * abs(e) + absolute
            if not abs(g - e) / lim <= worst:
                worst, worst_at = abs(g - e) / lim, (i % w, i // w, c, g, e)
            if not abs(g - e) <= lim:
                if bad < 5:
                    print(f"  pixel ({i % w}, {i // w}).{c}: GLSL {g!r} C++ {e!r} |diff| {abs(g - e):.3g} > {lim:.3g}")
                bad += 1
            d8 = max(d8, abs(srgb_png(g, 1.0) - srgb_png(e, 1.0)))
        hist[d8] = hist.get(d8, 0) + 1
        worst8 = max(worst8, d8)
    print(f"renderer: {result.get('renderer')}")
    print(f"pixels compared {compared} of {w * h} ({len(excluded)} excluded: their camera ray meets the room within "
          f"1e-3 of an edge between two walls)")
    print(f"linear RGB: worst |diff| / ({rel:g} |C++| + {absolute:g}) {worst:.3g} at pixel ({worst_at[0]}, {worst_at[1]}) "
          f"channel {worst_at[2]} (GLSL {worst_at[3]:.9g}, C++ {worst_at[4]:.9g}); {bad} values outside")
    print("8-bit (Reinhard, sRGB) max channel |diff| histogram: " + ", ".join(f"{k}: {hist[k]}" for k in sorted(hist)))
    # The mirror floor against the truth, per half (the same wall point in both halves).
    err = {0: [0.0, 0.0], 1: [0.0, 0.0]}
    for k, i in enumerate(fixtures["mirror"]):
        half = 1 if i % w >= w // 2 else 0
        t = luminance(fixtures["mirror_truth"][3 * k:3 * k + 3])
        g = luminance(vals[4 * i:4 * i + 3])
        err[half][0] += (g - t) ** 2
        err[half][1] += t * t
    rmse = {k: math.sqrt(v[0] / v[1]) if v[1] > 0 else float("inf") for k, v in err.items()}
    print(f"mirror floor ({len(fixtures['mirror']) // 2} pixels per half) against the true radiance, relative RMSE of "
          f"luminance: distant lookup {rmse[0]:.4f}, parallax-corrected {rmse[1]:.4f}")
    ok = bad == 0 and worst8 <= 1 and rmse[1] < 0.25 * rmse[0] and compared > 0.9 * w * h
    print("PASS" if ok else "FAIL")
    return ok


# ---- BC6H decoder comparison --------------------------------------------------------------------------

BC6H_MODES = {0x02: 3, 0x06: 4, 0x0a: 5, 0x0e: 6, 0x12: 7, 0x16: 8, 0x1a: 9, 0x1e: 10, 0x03: 11, 0x07: 12, 0x0b: 13, 0x0f: 14}


def bc6h_mode(block):
    """The mode (1..14) of a BC6H block from its low bits, or 'reserved 0bXXXXX'."""
    if block[0] & 3 < 2:
        return f"mode {1 + (block[0] & 3)}"
    code = block[0] & 0x1f
    return f"mode {BC6H_MODES[code]}" if code in BC6H_MODES else f"reserved {code:05b}"


def float_to_half_exact(f):
    """The half-float bit pattern of f if f is exactly a half (a BC6H texel always is), else None."""
    try:
        h = struct.unpack("<H", struct.pack("<e", f))[0]
    except OverflowError:
        return None
    back = struct.unpack("<e", struct.pack("<H", h))[0]
    return h if back == f and math.copysign(1.0, back) == math.copysign(1.0, f) else None


def compare_bc6h(fixtures, result):
    """Every texel of every block: the browser's decode (RGBA32F) against the library's halves, bit for bit."""
    blocks = base64.b64decode(fixtures["blocks"])
    halves = base64.b64decode(fixtures["halves"])
    per, count = fixtures["blocks_per_row"], fixtures["count"]
    w, h = result["width"], result["height"]
    if result["blocks"] != count or w != 4 * per or h != 4 * ((count + per - 1) // per):
        raise RuntimeError(f"the page decoded {result['blocks']} blocks into {w} x {h}, expected {count} blocks")
    got = struct.unpack(f"<{4 * w * h}f", base64.b64decode(result["rgba"]))
    expect = struct.unpack(f"<{48 * count}H", halves)
    by_mode, by_group, bad_blocks = {}, {}, []
    group_of = [None] * count
    for g in fixtures["groups"]:
        for i in range(g["first"], g["first"] + g["count"]):
            group_of[i] = g["name"]
    texels = 0
    for i in range(count):
        bx, by = i % per, i // per
        block = blocks[16 * i:16 * i + 16]
        mode = bc6h_mode(block)
        stats = by_mode.setdefault(mode, [0, 0, 0])  # blocks, texels, mismatching texels
        gstats = by_group.setdefault(group_of[i], [0, 0])  # blocks, mismatching blocks
        stats[0] += 1
        gstats[0] += 1
        wrong = []
        for t in range(16):
            x, y = 4 * bx + t % 4, 4 * by + t // 4
            k = 4 * (y * w + x)
            lib = expect[48 * i + 3 * t:48 * i + 3 * t + 3]
            gpu = [float_to_half_exact(got[k + c]) for c in range(3)]
            texels += 1
            stats[1] += 1
            if list(lib) != gpu:
                stats[2] += 1
                wrong.append((t, lib, [got[k + c] for c in range(3)]))
        if wrong:
            gstats[1] += 1
            bad_blocks.append((i, mode, group_of[i], block, wrong))
    print(f"renderer: {result['renderer']}")
    print(f"blocks compared {count}, texels {texels} (x 3 channels, every value's half bits); the library's values: "
          f"{sum(1 for v in expect if v)} of {len(expect)} nonzero, {len(set(expect))} distinct, largest "
          f"{struct.unpack('<e', struct.pack('<H', max(expect)))[0]:g}")
    print("per mode (blocks, texels, mismatching texels):")
    order = [f"mode {m}" for m in range(1, 15)] + sorted(k for k in by_mode if k.startswith("reserved"))
    for m in order:
        if m in by_mode:
            b, t, bad = by_mode[m]
            print(f"  {m:18s} {b:6d} blocks {t:7d} texels  {bad} mismatching")
    print("per group (blocks, mismatching blocks):")
    for g in fixtures["groups"]:
        b, bad = by_group[g["name"]]
        print(f"  {g['name']:48s} {b:6d}  {bad}")
    for i, mode, group, block, wrong in bad_blocks[:20]:
        print(f"MISMATCH block {i} ({group}, {mode}) bytes {block.hex()}:")
        for t, lib, gpu in wrong[:16]:
            gbits = [float_to_half_exact(v) for v in gpu]
            print(f"  texel {t} (x {t % 4}, y {t // 4}): library halves {[f'0x{v:04x}' for v in lib]} = "
                  f"{[struct.unpack('<e', struct.pack('<H', v))[0] for v in lib]}; browser {gpu} (half bits "
                  f"{[('0x%04x' % v) if v is not None else 'not a half' for v in gbits]})")
    if len(bad_blocks) > 20:
        print(f"... and {len(bad_blocks) - 20} more mismatching blocks")
    ok = not bad_blocks
    print("PASS" if ok else f"FAIL: {len(bad_blocks)} of {count} blocks differ")
    return ok


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--mode", choices=["preview", "numeric", "prefilter", "refilter", "bc6h", "room", "screenshot"], required=True)
    ap.add_argument("--page", choices=["viewer", "room"], default="viewer", help="screenshot: which page")
    ap.add_argument("--tool", help="ibl-bake (preview)")
    ap.add_argument("--reference", help="glsl_reference (numeric, prefilter), bc6h_fixtures (bc6h), room_reference (room)")
    ap.add_argument("--chromium", default="chromium")
    ap.add_argument("--repo", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
    ap.add_argument("--size", default="32", help="face size of the preview test's bake")
    ap.add_argument("--quality", default="low", help="quality of the preview test's bake")
    ap.add_argument("--input", help="the preview test's --input (default: the built-in sky)")
    ap.add_argument("--bake-args", default="", help="more ibl-bake options for the preview test, space separated")
    ap.add_argument("--keep", help="copy the bake folder and the page's pixels here")
    ap.add_argument("--timeout", type=float, default=120.0)
    ap.add_argument("--out", help="screenshot: the PNG to write")
    ap.add_argument("--query", default="", help="screenshot: more query parameters, e.g. '&roughness=0.3'")
    ap.add_argument("--window", default="1000,470", help="screenshot: window size W,H")
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="ibl-browser-")
    try:
        bake_dir = os.path.join(work, "bake")
        os.makedirs(bake_dir)
        if a.mode == "refilter":  # a fast-filter bake with a float chain: the viewer re-filters it live
            subprocess.run([a.tool, "--size", a.size, "--prefilter", "fast", "--ktx2-format", "rgba32f", "--out", bake_dir,
                            "--quiet"] + a.bake_args.split(), check=True, stdout=subprocess.DEVNULL)
        if a.mode in ("preview", "screenshot") and a.page == "viewer":
            subprocess.run([a.tool, "--size", a.size, "--quality", a.quality, "--out", bake_dir, "--quiet"] +
                           (["--input", a.input] if a.input else []) + a.bake_args.split(), check=True,
                           stdout=subprocess.DEVNULL)
        if a.mode == "numeric":  # the runtime rows' fixtures (a chain and a table), served to the page
            fixtures = subprocess.run([a.reference, "--fixtures"], check=True, capture_output=True, text=True).stdout
            open(os.path.join(bake_dir, "numeric_fixtures.json"), "w").write(fixtures)
        if a.mode == "prefilter":  # the source, the taps and the C++ chain, served to the page
            prefilter_fixtures = subprocess.run([a.reference, "--prefilter-fixtures"], check=True, capture_output=True,
                                                text=True).stdout
            open(os.path.join(bake_dir, "prefilter_fixtures.json"), "w").write(prefilter_fixtures)
        if a.mode == "room" or a.page == "room":  # the scene, the probes and the expected pixels
            room_fixtures = subprocess.run([a.reference], check=True, capture_output=True, text=True).stdout
            open(os.path.join(bake_dir, "room_fixtures.json"), "w").write(room_fixtures)
        if a.mode == "bc6h":  # the blocks and the library's halves; the page reads the blocks
            bc6h_fixtures = subprocess.run([a.reference], check=True, capture_output=True, text=True).stdout
            open(os.path.join(bake_dir, "bc6h_fixtures.json"), "w").write(bc6h_fixtures)
        server = Server(os.path.abspath(a.repo), bake_dir)
        if a.mode == "screenshot":
            try:
                url = f"http://127.0.0.1:{server.port}/tools/viewer/index.html?bake=/bake/&glsl=/include/ibl/glsl/{a.query}"
                if a.page == "room":
                    url = (f"http://127.0.0.1:{server.port}/tools/viewer/room.html?data=/bake/room_fixtures.json"
                           f"&glsl=/include/ibl/glsl/{a.query}")
                # --virtual-time-budget lets the page's fetches and first frame finish before the shot.
                subprocess.run([a.chromium, "--headless=new", "--use-angle=swiftshader", "--enable-unsafe-swiftshader",
                                "--no-sandbox", "--disable-gpu-sandbox", "--no-first-run",
                                "--disable-background-networking", "--disable-component-update", "--disable-sync",
                                f"--user-data-dir={os.path.join(work, 'profile')}", f"--window-size={a.window}",
                                "--virtual-time-budget=20000", "--hide-scrollbars", f"--screenshot={os.path.abspath(a.out)}",
                                url], check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=a.timeout)
            finally:
                server.close()
            return 0
        try:
            url = (f"http://127.0.0.1:{server.port}/tools/viewer/index.html?test={a.mode}&bake=/bake/"
                   f"&glsl=/include/ibl/glsl/&report=/result")
            if a.mode == "room":
                url = (f"http://127.0.0.1:{server.port}/tools/viewer/room.html?test=room&data=/bake/room_fixtures.json"
                       f"&glsl=/include/ibl/glsl/&report=/result")
            result = run_page(a.chromium, url, os.path.join(work, "profile"), a.timeout, server)
        finally:
            server.close()
        if result.get("kind") == "skip":
            print(f"SKIPPED: {result['reason']} (renderer {result.get('renderer')})")
            print("extensions: " + ", ".join(result.get("extensions") or []))
            return SKIP
        if a.mode == "preview":
            reference = None
            if result["info"]["chain_format"] in BLOCK_FORMATS or result["info"].get("irradiance_format") in BLOCK_FORMATS:
                reference = lookup_preview(a.tool, bake_dir, result["info"]["preview_ss"], work)
            ok = compare_preview(bake_dir, result, reference)
            if a.keep:
                os.makedirs(a.keep, exist_ok=True)
                shutil.copytree(bake_dir, os.path.join(a.keep, "bake"), dirs_exist_ok=True)
                open(os.path.join(a.keep, "browser_rgb.bin"), "wb").write(base64.b64decode(result["rgb"]))
        elif a.mode == "prefilter":
            ok = compare_prefilter(json.loads(prefilter_fixtures), result)
        elif a.mode == "refilter":
            report = json.load(open(os.path.join(bake_dir, "report.json")))
            mids = (report["specular"].get("mid_tail") or {}).get("mid_roughness_per_level") or []
            ok = compare_refilter(result, intermediate=sum(1 for r in mids if r is not None))
        elif a.mode == "room":
            ok = compare_room(json.loads(room_fixtures), result, ROOM_REL, ROOM_ABS)
        elif a.mode == "bc6h":
            ok = compare_bc6h(json.loads(bc6h_fixtures), result)
        else:
            ok = compare_numeric(a.reference, result)
        return 0 if ok else 1
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
