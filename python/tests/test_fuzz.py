# A seeded, deterministic fuzzer of the module's inputs (no Hypothesis): every public function is
# called with argument sets that mix valid values and hostile ones (0-size, odd shapes, strided and
# reversed views, float16 .. complex / object / bool dtypes, NaN / inf / -0 / 1e38, wrong keyword
# values, Python models that raise, return wrong shapes / dtypes / NaN or are not callable). A call
# must return (finite output where the docs promise it, an array of the right kind) or raise
# ValueError / TypeError / RuntimeError / OverflowError with a message; a model's own exception may
# propagate unchanged. The calls run in a child process (python3 test_fuzz.py SEED ITERS), so that
# a crash or a hang fails the test with the child's signal / output instead of killing pytest.
#
# IBL_FUZZ_ITERATIONS: argument sets per function and seed (default 200); IBL_FUZZ_SEEDS: how many
# seeds (default 2). Run by hand:  PYTHONPATH=build/dev/python python3 python/tests/test_fuzz.py 0 2000
import faulthandler
import math
import os
import subprocess
import sys
import time

import numpy as np

ALLOWED = (ValueError, TypeError, RuntimeError, OverflowError)


class ModelError(Exception):
    """Raised by the misbehaving models themselves: it must propagate unchanged."""


# ---------------------------------------------------------------------------------------------
# value generators

def _views(rng, x):
    """x itself, or the same values as a non-contiguous / reversed / Fortran view."""
    k = rng.integers(0, 5)
    if k == 0 or x.ndim == 0:
        return x
    if k == 1:  # a strided view of a larger array
        big = np.repeat(x, 2, axis=0)
        return big[::2]
    if k == 2:
        return x[::-1]
    if k == 3:
        return np.asfortranarray(x)
    return x.copy()


def _real(rng, lo, hi, shape):
    dt = rng.choice([np.float32, np.float64, np.float64])
    x = rng.uniform(lo, hi, size=shape).astype(dt)
    if shape == ():
        return float(x) if rng.random() < 0.5 else x[()]
    return _views(rng, x)


def _lead(rng):
    return [(), (3,), (2, 2), (1,), (4, 1), (0,), (1, 3)][rng.integers(0, 7)]


HOSTILE_SCALARS = [float("nan"), float("inf"), -float("inf"), -0.0, 1e38, -1e38, 1e308, 5e-324,
                   -1.0, 2.0, 0, 1, True, 2 ** 70, -2 ** 70]


def hostile(rng, core=1):
    """A value that is wrong for most parameters (or right in an odd way)."""
    k = rng.integers(0, 22)
    if k == 0:
        return None
    if k == 1:
        return "abc"
    if k == 2:
        return HOSTILE_SCALARS[rng.integers(0, len(HOSTILE_SCALARS))]
    if k == 3:
        return np.array([object(), 1.0], dtype=object)
    if k == 4:
        return np.ones((2, core) if core > 1 else (2,), dtype=np.complex128) * (0.5 + 0.5j)
    if k == 5:
        return np.ones((2, core) if core > 1 else (2,), dtype=bool)
    if k == 6:
        return np.ones((2, core) if core > 1 else (2,), dtype=np.int32)
    if k == 7:
        return np.full((3, core) if core > 1 else (3,), 0.5, dtype=np.float16)
    if k == 8:
        v = HOSTILE_SCALARS[rng.integers(0, 9)]
        return np.full((2, core) if core > 1 else (2,), v)
    if k == 9:
        return np.zeros((0, core) if core > 1 else (0,))
    if k == 10:
        return np.zeros((2, core + 1))  # wrong trailing axis
    if k == 11:
        return np.zeros((1,) * 20)  # many axes, one element
    if k == 12:
        return [[0.1, 0.2], [0.3]]  # ragged
    if k == 13:
        return {"a": 1}
    if k == 14:
        return np.broadcast_to(np.float64(0.5), (3, core) if core > 1 else (3,))  # 0 strides
    if k == 15:
        return np.array(0.5)[()]  # NumPy scalar
    if k == 16:
        return np.float32(float("nan"))
    if k == 17:
        return np.array(["a", "b"])
    if k == 18:
        return np.full((5, 7, core) if core > 1 else (5, 7), -0.25)
    if k == 19:
        return np.zeros((0, 0, core) if core > 1 else (0, 0))
    if k == 20:
        return np.ma.masked_array([0.5, 0.5], mask=[True, False])
    return np.uint8(3)


def gen_unit(rng, core=1, lead=None):
    """Values in [0, 1] (a scalar or a broadcasting array), hostile with probability 0.25."""
    if rng.random() < 0.25:
        return hostile(rng, core)
    shape = _lead(rng) if lead is None else lead
    if core > 1:
        shape = shape + (core,)
    return _real(rng, 0.0, 1.0, shape)


def gen_dir(rng, lead=None):
    if rng.random() < 0.25:
        return hostile(rng, 3)
    shape = (_lead(rng) if lead is None else lead) + (3,)
    x = rng.normal(size=shape)
    if rng.random() < 0.1:
        x[...] = 0.0  # zero vectors
    x = x.astype(rng.choice([np.float32, np.float64]))
    return _views(rng, x)


def gen_signed(rng, core=1):
    if rng.random() < 0.25:
        return hostile(rng, core)
    shape = _lead(rng) + ((core,) if core > 1 else ())
    return _real(rng, -1.5, 1.5, shape)


def gen_int(rng, lo, hi):
    if rng.random() < 0.2:
        return [-1, 0, -2 ** 40, 2 ** 31, 2 ** 63, 2 ** 70, 1.5, "4", None, True, np.int64(3),
                float("nan")][rng.integers(0, 12)]
    return int(rng.integers(lo, hi + 1))


def gen_float(rng, lo, hi):
    if rng.random() < 0.2:
        return HOSTILE_SCALARS[rng.integers(0, len(HOSTILE_SCALARS))]
    return float(rng.uniform(lo, hi))


def gen_str(rng, choices):
    if rng.random() < 0.2:
        return ["", "nope", None, 3, "GGX", b"fis", "fis\0"][rng.integers(0, 7)]
    return choices[rng.integers(0, len(choices))]


def gen_bool(rng):
    if rng.random() < 0.15:
        return [None, "yes", 2, np.bool_(True)][rng.integers(0, 4)]
    return bool(rng.integers(0, 2))


def gen_threads(rng):
    return [0, 1, 2, -1, 2 ** 40][rng.integers(0, 5)] if rng.random() < 0.3 else int(rng.integers(0, 3))


def gen_cube(rng, small=True):
    """A float32 (6, n, n, 3) cube, or something almost like one."""
    if rng.random() < 0.3:
        k = rng.integers(0, 12)
        if k == 0:
            return np.zeros((6, 0, 0, 3), np.float32)
        if k == 1:
            return np.ones((6, 4, 5, 3), np.float32)
        if k == 2:
            return np.ones((5, 4, 4, 3), np.float32)
        if k == 3:
            return np.ones((6, 4, 4, 4), np.float32)
        if k == 4:
            c = np.ones((6, 4, 4, 3), np.float32)
            c[1, 2, 3, 0] = [np.nan, np.inf, -np.inf][rng.integers(0, 3)]
            return c
        if k == 5:
            return np.full((6, 4, 4, 3), 1e38, np.float32)
        if k == 6:
            return -np.ones((6, 4, 4, 3), np.float32)
        if k == 7:
            return np.ones((6, 4, 4, 3), np.float64)  # converted
        if k == 8:
            return np.ones((6, 4, 4, 3), np.complex64)
        if k == 9:
            return np.ones((6, 1, 1, 3), np.float32)
        if k == 10:
            return np.ones((6, 3, 3, 3), np.float32)  # odd size
        return hostile(rng, 3)
    n = [4, 8, 2, 1][rng.integers(0, 4)] if small else 8
    c = rng.exponential(1.0, size=(6, n, n, 3)).astype(np.float32)
    if rng.random() < 0.2:
        c[rng.integers(0, 6), 0, 0] = 1e4  # a bright texel
    if rng.random() < 0.2:
        c[:] = 0.0
    return _views(rng, c)


# ---------------------------------------------------------------------------------------------
# Python models, well- and ill-behaved

def _ndf_ggx(n_dot_h, alpha):
    a2 = np.clip(alpha, 2.0 ** -255, 1.0) ** 2
    c = np.clip(n_dot_h, 0.0, 1.0)
    d = (1.0 - c) * (1.0 + c) + a2 * c * c
    return np.where(n_dot_h >= 0.0, a2 / (np.pi * d * d), 0.0)


def _vis(n_dot_v, n_dot_l, r):
    return np.full(np.shape(n_dot_v), 0.25)


class GoodModel:
    def __repr__(self):
        return type(self).__name__ + "()"

    def alpha(self, r):
        return np.asarray(r) ** 2

    def ndf(self, n_dot_h, alpha):
        return _ndf_ggx(n_dot_h, alpha)

    def visibility(self, n_dot_v, n_dot_l, r):
        return _vis(n_dot_v, n_dot_l, r)


def _bad(kind, shape):
    """A misbehaving result for an input of `shape`."""
    if kind == "raise":
        raise ModelError("model failure")
    if kind == "nan":
        return np.full(shape, np.nan)
    if kind == "inf":
        return np.full(shape, np.inf)
    if kind == "neg":
        return np.full(shape, -1.0)
    if kind == "short":
        return np.ones(max(int(np.prod(shape)) - 1, 0))
    if kind == "long":
        return np.ones(int(np.prod(shape)) + 3)
    if kind == "2d":
        return np.ones((1,) + tuple(shape))
    if kind == "str":
        return "x"
    if kind == "none":
        return None
    if kind == "obj":
        return np.array([object()] * int(np.prod(shape)), dtype=object)
    if kind == "complex":
        return np.ones(shape, dtype=np.complex128)
    if kind == "int":
        return np.ones(shape, dtype=np.int64)
    if kind == "f32":
        return np.ones(shape, dtype=np.float32)
    if kind == "scalar":
        return 0.5
    if kind == "zero":
        return np.zeros(shape)
    if kind == "huge":
        return np.full(shape, 1e308)
    if kind == "list":
        return [1.0] * int(np.prod(shape))
    if kind == "reversed":
        return np.ones(shape)[::-1]
    if kind == "keyerror":
        raise KeyError("inside the model")
    raise AssertionError(kind)


BAD_KINDS = ["raise", "nan", "inf", "neg", "short", "long", "2d", "str", "none", "obj", "complex",
             "int", "f32", "scalar", "zero", "huge", "list", "reversed", "keyerror"]


def make_model(rng):
    """A model object: good, or with one misbehaving / missing / non-callable method."""
    k = rng.integers(0, 12)
    if k < 3:
        return GoodModel()
    if k == 10:  # an attribute whose lookup raises
        class Prop(GoodModel):
            @property
            def ndf(self):
                raise ModelError("model failure")
        return Prop()
    if k == 11:  # a method returning an array subclass / a read-only view of its input
        class Odd(GoodModel):
            def alpha(self, r):
                a = np.asarray(r) ** 2
                return np.ma.masked_array(a, mask=np.zeros(a.shape, bool))

            def visibility(self, n_dot_v, n_dot_l, r):
                n_dot_v.setflags(write=False) if rng.random() < 0.5 else None
                return np.broadcast_to(0.25, np.shape(n_dot_v))
        return Odd()
    if k == 3:
        return object()  # no methods at all
    if k == 4:  # a method that is not callable
        m = GoodModel()
        setattr(m, ["alpha", "ndf", "visibility", "sample_weight"][rng.integers(0, 4)], 3)
        return m
    if k == 5:  # a method with the wrong arity
        m = GoodModel()
        m.ndf = lambda x: x
        return m
    if k == 6:  # only sample_weight
        bad = BAD_KINDS[rng.integers(0, len(BAD_KINDS))] if rng.random() < 0.7 else None

        class SW:
            def alpha(self, r):
                return np.asarray(r) ** 2

            def __repr__(self):
                return f"SampleWeightModel({bad})"

            def sample_weight(self, nv, nl, nh, vh, r):
                if bad is not None:
                    return _bad(bad, np.shape(nv))
                return np.where(np.asarray(nl) > 0, 0.5, 0.0)
        return SW()
    which = ["alpha", "ndf", "visibility"][rng.integers(0, 3)]
    bad = BAD_KINDS[rng.integers(0, len(BAD_KINDS))]

    class Bad(GoodModel):
        def __repr__(self):
            return f"BadModel({which}: {bad})"

    def method(self, *args):
        return _bad(bad, np.shape(args[0]))
    setattr(Bad, which, method)
    return Bad()


def gen_model(rng, names, allow_none=False):
    if rng.random() < 0.5:
        return make_model(rng)
    pool = list(names) + ["nope", 3, b"ggx"] + ([None] if allow_none else [])
    return pool[rng.integers(0, len(pool))]


# ---------------------------------------------------------------------------------------------
# per-function argument generators: fn(rng) -> (args, kwargs, checks)
# checks: a dict of what a successful return must satisfy ("finite": bool, "kind": ...)

import ibl  # noqa: E402

MODELS = tuple(ibl.builtin_models)


def unit_or_signed(rng):
    return gen_unit(rng) if rng.random() < 0.7 else gen_signed(rng)


def elementwise(*cores):
    """An element-wise function of len(cores) arguments: 'u' unit scalar, 's' signed scalar,
    'u2' unit pair, 'd' direction."""
    def gen(rng):
        lead = _lead(rng) if rng.random() < 0.6 else None
        args = []
        for c in cores:
            if c == "u":
                args.append(gen_unit(rng, 1, lead) if rng.random() < 0.85 else gen_signed(rng))
            elif c == "s":
                args.append(gen_signed(rng))
            elif c == "u2":
                args.append(gen_unit(rng, 2, lead))
            elif c == "d":
                args.append(gen_dir(rng, lead))
        return args, {}, {}
    return gen


def g_hammersley(rng):
    kw = {"float32": gen_bool(rng)} if rng.random() < 0.5 else {}
    return [gen_int(rng, 0, 64)], kw, {"finite": True}


def g_dfg(rng):
    kw = {"threads": gen_threads(rng)} if rng.random() < 0.3 else {}
    args = [gen_unit(rng), gen_unit(rng)]
    if rng.random() < 0.7:
        args.append(gen_model(rng, MODELS))
    return args, kw, {"finite": True}


def g_dfg_lut(rng):
    kw = {}
    if rng.random() < 0.5:
        kw["layout"] = gen_str(rng, ["uniform", "remapped", "sqrt"])
    if rng.random() < 0.5:
        kw["multiscatter"] = gen_bool(rng)
    if rng.random() < 0.3:
        kw["threads"] = gen_threads(rng)
    args = [gen_int(rng, 1, 6)]
    if rng.random() < 0.6:
        args.append(gen_model(rng, MODELS))
    return args, kw, {"finite": True}


def g_dfg_lut_coords(rng):
    args = [gen_int(rng, 1, 8)]
    if rng.random() < 0.5:
        args.append(gen_str(rng, ["uniform", "remapped"]))
    return args, {}, {"finite": True}


def g_dfg_mc(rng):
    args = [gen_unit(rng), gen_unit(rng), gen_int(rng, 1, 16)]
    if rng.random() < 0.6:
        args.append(gen_model(rng, MODELS))
    kw = {"sampling": gen_str(rng, ["ndf", "vndf"])} if rng.random() < 0.5 else {}
    return args, kw, {}


def g_dfg_albedo(rng):
    args = [gen_unit(rng), gen_unit(rng)]
    if rng.random() < 0.6:
        args.append(gen_model(rng, MODELS))
    return args, {}, {"finite": True}


def g_prefilter(rng):
    kw = {}
    if rng.random() < 0.5:
        kw["levels"] = gen_int(rng, -1, 4)
    kw["samples"] = gen_int(rng, 1, 8) if rng.random() < 0.8 else 0
    if rng.random() < 0.5:
        kw["method"] = gen_str(rng, ["fis", "importance", "fast"])
    if rng.random() < 0.3:
        kw["weight"] = gen_str(rng, ["n_dot_l", "g1"])
    if rng.random() < 0.3:
        kw["threads"] = gen_threads(rng)
    if rng.random() < 0.4:
        kw["model"] = make_model(rng) if rng.random() < 0.7 else gen_str(rng, ["ggx"])
    if rng.random() < 0.3:
        kw["peaks"] = [None, 0, 1, 2, -1, 2 ** 40][rng.integers(0, 6)]
    return [gen_cube(rng)], kw, {"finite": True, "kind": "levels"}


def g_irradiance(rng):
    args = [gen_cube(rng)]
    if rng.random() < 0.7:
        args.append(gen_int(rng, 1, 4))
    kw = {"samples": gen_int(rng, 1, 16)}
    if rng.random() < 0.5:
        kw["method"] = gen_str(rng, ["cosine", "riemann", "texel_moments"])
    if rng.random() < 0.3:
        kw["threads"] = gen_threads(rng)
    return args, kw, {"finite": True, "kind": "cube"}


def g_sh_project(rng):
    args = [gen_cube(rng)]
    if rng.random() < 0.6:
        args.append(gen_int(rng, 1, 5))
    return args, {}, {"finite": True}


def g_sh_evaluate(rng):
    b = int(rng.integers(1, 4))
    coeffs = _real(rng, -1, 1, (b * b, 3)) if rng.random() < 0.75 else hostile(rng, 3)
    return [coeffs, gen_dir(rng)], {}, {}


def g_sh_irradiance(rng):
    b = int(rng.integers(1, 5))
    coeffs = _real(rng, -1, 1, (b * b, 3)) if rng.random() < 0.75 else hostile(rng, 3)
    return [coeffs], {}, {}


def g_reference_ld(rng):
    kw = {}
    if rng.random() < 0.3:
        kw["weight"] = gen_str(rng, ["n_dot_l", "g1"])
    if rng.random() < 0.3:
        kw["threads"] = gen_threads(rng)
    if rng.random() < 0.4:
        kw["model"] = make_model(rng) if rng.random() < 0.7 else gen_str(rng, ["ggx"])
    lead = _lead(rng)
    return [gen_cube(rng), gen_dir(rng, lead), gen_unit(rng, 1, lead), gen_int(rng, 1, 16)], kw, {"finite": True}


def g_extract_sun(rng):
    kw = {}
    for name, lo, hi in [("threshold_over_median", 1, 100), ("threshold_over_peak", 0, 1),
                         ("max_solid_angle", 0, 1), ("min_share", 0, 1)]:
        if rng.random() < 0.3:
            kw[name] = gen_float(rng, lo, hi)
    if rng.random() < 0.3:
        kw["threads"] = gen_threads(rng)
    return [gen_cube(rng)], kw, {"finite": True}


def g_reference_radiance(rng):
    lead = _lead(rng)
    args = [gen_cube(rng), gen_dir(rng, lead), gen_dir(rng, lead), gen_unit(rng, 3, lead),
            gen_unit(rng, 1, lead), gen_unit(rng, 1, lead)]
    kw = {"samples": gen_int(rng, 1, 8), "batches": gen_int(rng, 2, 3)}
    if rng.random() < 0.3:
        kw["seed"] = gen_int(rng, 0, 100)
    if rng.random() < 0.4:
        kw["strategy"] = gen_str(rng, ["mis", "brdf", "env"])
    if rng.random() < 0.3:
        kw["diffuse"] = gen_str(rng, ["lambert", "one_minus_fresnel_roughness"])
    if rng.random() < 0.3:
        kw["dielectric_f0"] = gen_float(rng, 0, 1)
    if rng.random() < 0.3:
        kw["threads"] = gen_threads(rng)
    if rng.random() < 0.4:
        kw["model"] = make_model(rng) if rng.random() < 0.7 else gen_str(rng, ["ggx"])
    return args, kw, {"finite": True}


_TMP = None


def _tmpdir():
    global _TMP
    if _TMP is None:
        import tempfile
        _TMP = tempfile.mkdtemp(prefix="ibl_fuzz_")
    return _TMP


def _tiny_hdr(rng, h=4, w=8):
    """A small flat (uncompressed) Radiance RGBE file."""
    px = rng.integers(0, 256, size=(h, w, 4), dtype=np.uint8)
    px[..., 3] = rng.integers(100, 160, size=(h, w))
    return b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n" + f"-Y {h} +X {w}\n".encode() + px.tobytes()


def _mutate(rng, data):
    """Bytes flipped, cut short or with a header field replaced."""
    b = bytearray(data)
    k = rng.integers(0, 5)
    if k == 0 and b:
        for _ in range(int(rng.integers(1, 9))):
            b[int(rng.integers(0, len(b)))] = int(rng.integers(0, 256))
    elif k == 1:
        b = b[:int(rng.integers(0, len(b) + 1))]
    elif k == 2:
        b = b.replace(b"-Y 4 +X 8", [b"-Y 99999999 +X 99999999", b"-Y -4 +X 8", b"-Y 0 +X 0",
                                     b"+X 8 -Y 4", b"-Y 4 +X 9999999999999999999"][rng.integers(0, 5)])
    elif k == 3 and len(b) > 16:  # a header from a real file, its data cut off
        b = b[:16] + bytes(rng.integers(0, 256, size=int(rng.integers(0, 256)), dtype=np.uint8))
    return bytes(b)


_EXR_HEAD = None


def _exr_head():
    """The first 64 KiB of a test EXR (header and offset table intact, data cut), when available."""
    global _EXR_HEAD
    if _EXR_HEAD is None:
        _EXR_HEAD = b""
        d = os.environ.get("IBL_TEST_DATA") or os.path.join(os.path.dirname(__file__), "..", "..", "tests", "data")
        p = os.path.join(d, "studio.exr")
        if os.path.exists(p):
            with open(p, "rb") as f:
                _EXR_HEAD = f.read(65536)
    return _EXR_HEAD


def _fuzz_file(rng, base, suffix):
    path = os.path.join(_tmpdir(), f"f{rng.integers(0, 1 << 30)}{suffix}")
    with open(path, "wb") as f:
        f.write(_mutate(rng, base) if rng.random() < 0.8 else base)
    return path


KTX2_MAGIC = b"\xabKTX 20\xbb\r\n\x1a\n"


def _tiny_ktx2(rng):
    """The KTX2 identifier, then a header of random / extreme 32-bit fields and a little data."""
    fields = rng.choice(np.array([0, 1, 2, 4, 6, 97, 0xFFFFFFFF, 0x7FFFFFFF, 64, 80], dtype=np.uint32), size=17)
    return KTX2_MAGIC + fields.astype("<u4").tobytes() + bytes(rng.integers(0, 256, size=int(rng.integers(0, 512)),
                                                                            dtype=np.uint8))


def g_read_image(rng):
    if rng.random() < 0.6:
        base = _exr_head() if rng.random() < 0.3 else _tiny_hdr(rng)
        paths = [_fuzz_file(rng, base or _tiny_hdr(rng), ".hdr")]
    else:
        paths = ["/nonexistent/x.hdr", "", "/", "/dev/null", "/proc/self/status", __file__, "\0x",
                 3, None, b"/tmp"]
    kw = {}
    if rng.random() < 0.4:
        kw["latlong"] = gen_bool(rng)
    if rng.random() < 0.4:
        kw["max_pixels"] = gen_int(rng, 0, 1 << 20)
    if rng.random() < 0.3:
        kw["replace_nonfinite"] = gen_bool(rng)
    return [paths[rng.integers(0, len(paths))]], kw, {"finite": True}


def g_read_ktx2(rng):
    if rng.random() < 0.6:
        return [_fuzz_file(rng, _tiny_ktx2(rng), ".ktx2")], {}, {}
    paths = ["/nonexistent/x.ktx2", "", "/", "/dev/null", __file__, 3, None]
    return [paths[rng.integers(0, len(paths))]], {}, {}


def g_cube_from_latlong(rng):
    if rng.random() < 0.75:
        h = int(rng.integers(1, 9))
        img = _real(rng, 0, 2, (h, 2 * h, 3))
    else:
        img = hostile(rng, 3)
    args = [img, gen_int(rng, 1, 4)]
    if rng.random() < 0.5:
        args.append(gen_int(rng, 1, 3))
    kw = {"threads": gen_threads(rng)} if rng.random() < 0.3 else {}
    return args, kw, {"finite": True, "kind": "cube"}


def g_specular_lookup(rng):
    if rng.random() < 0.8:
        n = 4
        chain = []
        while n >= 1 and len(chain) < 3:
            chain.append(rng.uniform(0, 1, size=(6, n, n, 3)).astype(np.float32))
            n //= 2
        if rng.random() < 0.2:
            chain = chain[::-1]  # levels growing
        if rng.random() < 0.1:
            chain = []
        if rng.random() < 0.1:
            chain = [c.astype(np.float64) for c in chain]
    else:
        k = rng.integers(0, 5)
        if k == 0:
            chain = [gen_cube(rng), hostile(rng, 3)]
        elif k == 1:
            chain = "abc"
        elif k == 2:
            chain = np.ones((2, 6, 4, 4, 3), np.float32)  # an array as the sequence of levels
        elif k == 3:
            chain = (c for c in [np.ones((6, 4, 4, 3), np.float32)])  # a generator
        else:
            chain = hostile(rng, 3)
    lead = _lead(rng)
    kw = {}
    if rng.random() < 0.4:
        kw["lookup"] = gen_str(rng, ["textbook", "accurate"])
    if rng.random() < 0.4:
        kw["mapping"] = gen_str(rng, ["linear", "filament"])
    return [chain, gen_dir(rng, lead), gen_unit(rng, 1, lead)], kw, {"finite": True}


def g_dfg_lookup(rng):
    if rng.random() < 0.8:
        s = int(rng.integers(1, 5))
        lut = _real(rng, 0, 1, (s, s, int(rng.integers(1, 4))))
    else:
        lut = hostile(rng, 2)
    kw = {"layout": gen_str(rng, ["uniform", "remapped"])} if rng.random() < 0.4 else {}
    return [lut, gen_unit(rng), gen_unit(rng)], kw, {"finite": True}


def g_shade_ambient(rng):
    lead = _lead(rng)
    args = [gen_unit(rng, 1, lead), gen_unit(rng, 3, lead), gen_unit(rng, 2, lead),
            gen_unit(rng, 3, lead), gen_unit(rng, 3, lead), gen_unit(rng, 1, lead),
            gen_unit(rng, 1, lead)]
    kw = {}
    if rng.random() < 0.3:
        kw["ao"] = gen_unit(rng)
    if rng.random() < 0.3:
        kw["dielectric_f0"] = gen_float(rng, 0, 1)
    if rng.random() < 0.3:
        kw["multiscatter"] = gen_bool(rng)
    return args, kw, {"finite": True}


GENERATORS = {
    "hammersley": g_hammersley,
    "sample_ggx_ndf": elementwise("u2", "u"),
    "ggx_ndf_pdf": elementwise("d", "u"),
    "ggx_ndf_reflected_pdf": elementwise("d", "d", "u"),
    "sample_ggx_vndf": elementwise("d", "u2", "u"),
    "ggx_vndf_pdf": elementwise("d", "d", "u"),
    "ggx_vndf_reflected_pdf": elementwise("d", "d", "u"),
    "alpha_from_roughness": elementwise("u"),
    "ndf_ggx": elementwise("s", "u"),
    "g1_smith_ggx": elementwise("s", "u"),
    "lambda_ggx": elementwise("s", "u"),
    "v_smith_ggx_correlated": elementwise("s", "s", "u"),
    "g2_smith_ggx_correlated": elementwise("s", "s", "u"),
    "k_ibl": elementwise("u"),
    "k_direct": elementwise("u"),
    "g1_schlick_ggx": elementwise("s", "u"),
    "g_smith_schlick_ggx": elementwise("s", "s", "u"),
    "v_smith_schlick_ggx": elementwise("s", "s", "u"),
    "schlick_weight": elementwise("s"),
    "fresnel_schlick": elementwise("s", "s", "s"),
    "fresnel_schlick_roughness": elementwise("s", "s", "u"),
    "ndf_blinn_phong": elementwise("s", "u"),
    "blinn_phong_exponent_from_alpha": elementwise("u"),
    "ndf_charlie": elementwise("s", "u"),
    "v_neubelt": elementwise("s", "s"),
    "dfg": g_dfg,
    "dfg_lut": g_dfg_lut,
    "dfg_smooth_limit": elementwise("u"),
    "dfg_lut_coords": g_dfg_lut_coords,
    "dfg_mc": g_dfg_mc,
    "dfg_albedo": g_dfg_albedo,
    "dfg_energy_compensation": elementwise("u"),
    "prefilter": g_prefilter,
    "irradiance": g_irradiance,
    "sh_project": g_sh_project,
    "sh_evaluate": g_sh_evaluate,
    "sh_irradiance": g_sh_irradiance,
    "reference_ld": g_reference_ld,
    "extract_sun": g_extract_sun,
    "reference_radiance": g_reference_radiance,
    "read_image": g_read_image,
    "read_ktx2": g_read_ktx2,
    "cube_from_latlong": g_cube_from_latlong,
    "specular_lookup": g_specular_lookup,
    "dfg_lookup": g_dfg_lookup,
    "shade_ambient": g_shade_ambient,
}

# Functions whose calls cost more: fewer argument sets (a fraction of the iterations).
HEAVY = {"prefilter": 0.25, "irradiance": 0.25, "reference_ld": 0.25, "reference_radiance": 0.25,
         "dfg_lut": 0.25, "extract_sun": 0.5, "cube_from_latlong": 0.5, "dfg_mc": 0.5}


def public_functions():
    return sorted(n for n in dir(ibl) if not n.startswith("_") and callable(getattr(ibl, n)))


def _all_finite_inputs(args, kwargs):
    """True when every array-like argument is real and finite (then a finite result is due)."""
    for a in list(args) + list(kwargs.values()):
        if isinstance(a, (str, bytes, type(None), bool, int)) or hasattr(a, "alpha") or isinstance(a, list):
            continue
        try:
            x = np.asarray(a)
        except Exception:
            return False
        if x.dtype.kind not in "f" or not np.all(np.isfinite(x)):
            return False
    return True


def _check_result(name, res, checks, args, kwargs):
    arrays = []
    if checks.get("kind") == "levels":
        assert isinstance(res, list) and res, f"{name}: expected a non-empty list of levels"
        n = None
        for lv in res:
            assert isinstance(lv, np.ndarray) and lv.ndim == 4 and lv.shape[0] == 6 and lv.shape[3] == 3, \
                f"{name}: level of shape {getattr(lv, 'shape', None)}"
            assert lv.dtype == np.float32, f"{name}: level dtype {lv.dtype}"
            assert n is None or lv.shape[1] <= n, f"{name}: levels grow"
            n = lv.shape[1]
            arrays.append(lv)
    elif checks.get("kind") == "cube":
        assert isinstance(res, np.ndarray) and res.ndim == 4 and res.shape[0] == 6 and res.shape[3] == 3, \
            f"{name}: cube of shape {getattr(res, 'shape', None)}"
        arrays.append(res)
    elif isinstance(res, np.ndarray):
        assert res.dtype.kind == "f", f"{name}: result dtype {res.dtype}"
        arrays.append(res)
    elif isinstance(res, tuple):
        for x in res:
            if isinstance(x, np.ndarray):
                arrays.append(x)
            elif isinstance(x, dict):
                arrays.extend(np.asarray(v, dtype=float) for v in x.values())
    elif isinstance(res, dict):
        for k, v in res.items():
            assert isinstance(v, np.ndarray) and v.dtype.kind == "f", f"{name}: result[{k!r}] is {type(v)}"
            arrays.append(v)
    elif isinstance(res, float) or res is None or isinstance(res, list):
        if isinstance(res, float):
            arrays.append(np.asarray(res))
    else:
        raise AssertionError(f"{name}: unexpected result type {type(res)}")
    if checks.get("finite") and _all_finite_inputs(args, kwargs):
        for a in arrays:
            assert np.all(np.isfinite(a)), f"{name}: non-finite output from finite input"


def _describe(x):
    if isinstance(x, np.ndarray):
        extra = ""
        if x.dtype.kind == "f" and x.size:
            extra = f", max |x| {np.max(np.abs(x)):.3g}"
        return f"ndarray(shape={x.shape}, dtype={x.dtype}, strides={x.strides}{extra})"
    if isinstance(x, list) and x and isinstance(x[0], np.ndarray):
        return "[" + ", ".join(_describe(e) for e in x) + "]"
    r = repr(x)
    return r if len(r) < 80 else r[:77] + "..."


def run(seed, iterations, only=None, trace=False):
    """Fuzz every public function; returns (calls, failures)."""
    names = public_functions()
    missing = [n for n in names if n not in GENERATORS]
    if missing:
        return 0, [f"no fuzz generator for the public function(s) {missing}"]
    failures = []
    calls = 0
    np.seterr(all="ignore")
    for fi, name in enumerate(names):
        if only and name != only:
            continue
        fn = getattr(ibl, name)
        n = max(1, int(iterations * HEAVY.get(name, 1.0)))
        for i in range(n):
            rng = np.random.default_rng([seed, fi, i])
            args, kwargs, checks = GENERATORS[name](rng)
            call = f"ibl.{name}({', '.join(map(_describe, args))}" + \
                "".join(f", {k}={_describe(v)}" for k, v in kwargs.items()) + f")  [seed {seed}, {i}]"
            if trace:
                print(call, file=sys.stderr, flush=True)
            calls += 1
            try:
                res = fn(*args, **kwargs)
            except ALLOWED as e:
                if not str(e):
                    failures.append(f"{call}: {type(e).__name__} without a message")
                continue
            except (ModelError, KeyError) as e:
                if not (isinstance(e, ModelError) and str(e) == "model failure") and \
                        not (isinstance(e, KeyError) and "inside the model" in str(e)):
                    failures.append(f"{call}: {type(e).__name__}: {e}")
                continue
            except Exception as e:  # noqa: BLE001
                failures.append(f"{call}: {type(e).__name__}: {e}")
                continue
            if GENERATORS[name].__name__ == "gen" and any(a is None for a in args):
                failures.append(f"{call}: accepted None as a number (NumPy makes it NaN)")
                continue
            try:
                _check_result(name, res, checks, args, kwargs)
            except AssertionError as e:
                failures.append(f"{call}: {e}")
    return calls, failures


# ---------------------------------------------------------------------------------------------
# pytest: the fuzz body runs in a child process

def _iterations():
    return int(os.environ.get("IBL_FUZZ_ITERATIONS", "200"))


def _seeds():
    return int(os.environ.get("IBL_FUZZ_SEEDS", "2"))


def test_every_public_function_has_a_generator():
    assert [n for n in public_functions() if n not in GENERATORS] == []


def test_fuzz():
    iters = _iterations()
    timeout = max(120, iters * _seeds())
    for seed in range(_seeds()):
        t0 = time.time()
        p = subprocess.run([sys.executable, __file__, str(seed), str(iters)], capture_output=True,
                           text=True, timeout=timeout)
        tail = (p.stdout + p.stderr)[-6000:]
        assert p.returncode == 0, f"fuzz seed {seed}: exit {p.returncode} after {time.time() - t0:.1f} s\n{tail}"


def test_model_errors_propagate():
    # regression: a model's own exception comes out unchanged
    class M(GoodModel):
        def ndf(self, n_dot_h, alpha):
            raise ModelError("model failure")
    for call in (lambda: ibl.dfg(0.5, 0.5, M()), lambda: ibl.dfg_albedo(0.5, 0.5, M())):
        try:
            call()
        except ModelError:
            pass
        else:
            raise AssertionError("the model's exception was swallowed")


def _raises(exc, fn, *args, match=None, **kwargs):
    try:
        fn(*args, **kwargs)
    except exc as e:
        assert match is None or match in str(e), f"{type(e).__name__}: {e}"
        return
    raise AssertionError(f"{fn.__name__} did not raise {exc.__name__}")


# Regressions: what the fuzzer found (each once a silent wrong or non-finite result).

def test_complex_refused():
    z = np.full(3, 0.5 + 0.5j)
    _raises(TypeError, ibl.ndf_ggx, z, 0.5, match="complex")
    _raises(TypeError, ibl.ndf_ggx, 0.5, 0.5 + 0j, match="complex")
    _raises(TypeError, ibl.dfg, 0.5, z, match="complex")
    _raises(TypeError, ibl.sh_project, np.ones((6, 4, 4, 3), np.complex64), match="complex")
    _raises(TypeError, ibl.sh_irradiance, np.ones((9, 3), np.complex128), match="complex")
    _raises(TypeError, ibl.dfg_lookup, np.ones((4, 4, 2), np.complex64), 0.5, 0.5, match="complex")
    _raises(TypeError, ibl.specular_lookup, [np.ones((6, 4, 4, 3), np.complex64)], [0, 0, 1.0], 0.5, match="complex")
    _raises(TypeError, ibl.cube_from_latlong, np.ones((4, 8, 3), np.complex64), 4, match="complex")

    class ComplexNdf(GoodModel):
        def ndf(self, n_dot_h, alpha):
            return _ndf_ggx(n_dot_h, alpha) + 0j
    _raises(TypeError, ibl.dfg, 0.5, 0.5, ComplexNdf(), match="complex")
    _raises(TypeError, ibl.reference_ld, np.ones((6, 4, 4, 3), np.float32), [0, 0, 1.0], 0.5, 16,
            model=ComplexNdf(), match="complex")
    _raises(TypeError, ibl.reference_radiance, np.ones((6, 4, 4, 3), np.float32), [0, 0, 1.0], [0, 0, 1.0],
            [0.5] * 3, 0.0, 0.5, samples=4, batches=2, model=ComplexNdf(), match="complex")


def test_none_refused():
    _raises(TypeError, ibl.fresnel_schlick, 0.5, None, 1.0, match="None")
    _raises(TypeError, ibl.ndf_ggx, None, 0.5, match="None")
    _raises(TypeError, ibl.dfg, 0.5, None, match="None")
    _raises(TypeError, ibl.shade_ambient, 0.5, [1.0] * 3, [0.5, 0.1], [1.0] * 3, [0.5] * 3, 0.0, 0.5, ao=None, match="None")


def test_overflowing_cube_refused():
    big = np.full((6, 4, 4, 3), 1e38, np.float32)
    _raises(ValueError, ibl.sh_project, big, match="not finite")
    _raises(ValueError, ibl.irradiance, big, 2, samples=8, match="not finite")
    _raises(ValueError, ibl.prefilter, big, levels=0, samples=0, match="not finite")
    # a finite, ordinary cube still passes
    assert np.all(np.isfinite(ibl.sh_project(np.ones((6, 4, 4, 3), np.float32))))


def test_overflowing_model_refused():
    class Huge(GoodModel):
        def visibility(self, n_dot_v, n_dot_l, r):
            return np.full(np.shape(n_dot_v), 1e308)

    class ZeroNdf(GoodModel):
        def ndf(self, n_dot_h, alpha):
            return np.zeros(np.shape(n_dot_h))
    _raises(ValueError, ibl.dfg, 0.5, 0.5, Huge(), match="not finite")
    _raises(ValueError, ibl.dfg_albedo, 0.5, 0.5, Huge(), match="not finite")
    _raises(ValueError, ibl.dfg_mc, 0.5, 0.5, 8, Huge(), match="not finite")
    _raises(ValueError, ibl.dfg_lut, 2, Huge(), match="not finite")
    _raises(ValueError, ibl.dfg_lut, 2, ZeroNdf(), multiscatter=True, match="not finite")
    assert np.all(np.isfinite(ibl.dfg_lut(2, ZeroNdf())))  # E = 0 without the multiscatter channel


def test_reference_ld_infinite_dirs_refused():
    cube = np.ones((6, 4, 4, 3), np.float32)
    _raises(ValueError, ibl.reference_ld, cube, [np.inf, 0, 1.0], 0.5, 16, match="dirs")
    _raises(ValueError, ibl.reference_ld, cube, [1e200, 0, 1.0], 0.5, 16, match="dirs")


if __name__ == "__main__":
    faulthandler.enable()
    seed = int(sys.argv[1]) if len(sys.argv) > 1 else 0
    iters = int(sys.argv[2]) if len(sys.argv) > 2 else _iterations()
    only = sys.argv[3] if len(sys.argv) > 3 and sys.argv[3] != "-" else None
    trace = os.environ.get("IBL_FUZZ_TRACE") == "1"
    faulthandler.dump_traceback_later(max(60, iters), exit=True)  # a hang: traceback and exit
    t0 = time.time()
    try:
        calls, failures = run(seed, iters, only, trace)
    finally:
        if _TMP is not None:
            import shutil
            shutil.rmtree(_TMP, ignore_errors=True)
    for f in failures[:40]:
        print("FAIL", f)
    print(f"seed {seed}: {calls} calls, {len(failures)} failures, {time.time() - t0:.1f} s")
    sys.exit(1 if failures else 0)
