// tools/viewer/refilter.js — what the viewer needs to re-filter a chain on the GPU with
// include/ibl/glsl/ibl_prefilter.glsl: the source packed as the C++ kernel reads it (every level's
// faces with a 1-texel border, levels by the exact solid-angle box filter: ibl::cubemap's
// generate_mips and update_borders, ibl::detail::pack_cube) and the fast filter's taps per level
// (ibl::make_fast_ld_table with the shapes of include/ibl/bake/prefilter_fast_tables.hpp, split
// into single-level taps as ibl::detail::make_taps). Written after the C++ (same formulas, same
// order), in double; tests/browser/run_browser_test.py --mode prefilter compares both with the C++.

// ---- cube geometry (env/cube_geometry.hpp) ------------------------------------------------------

function facePoint(face, sc, tc) {
    switch (face) {
    case 0: return [1, -tc, -sc];
    case 1: return [-1, -tc, sc];
    case 2: return [sc, 1, tc];
    case 3: return [sc, -1, -tc];
    case 4: return [sc, -tc, 1];
    default: return [-sc, -tc, -1];
    }
}

/// Face and (s, t) of a direction: the GL table with ties X before Y before Z.
function faceSt(d) {
    const ax = Math.abs(d[0]), ay = Math.abs(d[1]), az = Math.abs(d[2]);
    const xm = ax >= ay && ax >= az, ym = !xm && ay >= az;
    const ma = xm ? ax : ym ? ay : az, major = xm ? d[0] : ym ? d[1] : d[2];
    const sg = major < 0 ? -1 : 1;
    const sc = xm ? -sg * d[2] : ym ? d[0] : sg * d[0];
    const tc = ym ? sg * d[2] : -d[1];
    return [(xm ? 0 : ym ? 2 : 4) + (major < 0 ? 1 : 0), 0.5 * sc / ma + 0.5, 0.5 * tc / ma + 0.5];
}

/// Exact solid angle of texel (x, y) of an n x n face.
function texelSolidAngle(x, y, n) {
    const F = (u, v) => Math.atan2(u * v, Math.sqrt(u * u + v * v + 1));
    const u0 = 2 * x / n - 1, u1 = 2 * (x + 1) / n - 1, v0 = 2 * y / n - 1, v1 = 2 * (y + 1) / n - 1;
    return F(u1, v1) - F(u0, v1) - F(u1, v0) + F(u0, v0);
}

/// The face texel across the edge from border texel (x, y) (cubemap.hpp fold_border).
function foldBorder(face, x, y, n) {
    const a = 2 * x + 1 - n, b = 2 * y + 1 - n;
    const ma = facePoint(face, 0, 0), s1 = facePoint(face, 1, 0), t1 = facePoint(face, 0, 1);
    const p = [0, 1, 2].map((k) => n * ma[k] + a * (s1[k] - ma[k]) + b * (t1[k] - ma[k]));
    for (let k = 0; k < 3; ++k) {
        if (Math.abs(p[k]) > n) {
            p[k] = Math.sign(p[k]) * n;
            for (let j = 0; j < 3; ++j) if (ma[j] !== 0) p[j] = ma[j] * (n - 1);
            break;
        }
    }
    const [g, s, t] = faceSt(p);
    return [g, Math.min(Math.floor(s * n), n - 1), Math.min(Math.floor(t * n), n - 1)];
}

// ---- the packed source ------------------------------------------------------------------------------

/// Packs level 0 (six faces of n x n RGB(A) texels, `rgbOf(face, x, y)` -> [r, g, b]) with its
/// full mip chain (power-of-two n): { data: Float32Array (4 per texel), levels: [{n, stride,
/// faceStride, offset}] }, the layout of ibl::detail::pack_cube.
export function packSource(n, rgbOf) {
    if (!(n >= 1) || (n & (n - 1)) !== 0) throw new Error(`re-filtering needs a power-of-two face, got ${n}`);
    const levels = [];
    let total = 0;
    for (let m = n; ; m >>= 1) {
        levels.push({ n: m, stride: m + 2, faceStride: (m + 2) * (m + 2), offset: total });
        total += 6 * (m + 2) * (m + 2);
        if (m === 1) break;
    }
    const data = new Float32Array(4 * total);
    const at = (lv, f, x, y) => 4 * (lv.offset + f * lv.faceStride + (y + 1) * lv.stride + (x + 1));
    let fine = null; // the previous level's interior, double, 3 per texel
    levels.forEach((lv, l) => {
        const m = lv.n, cur = new Float64Array(6 * m * m * 3);
        for (let f = 0; f < 6; ++f)
            for (let y = 0; y < m; ++y)
                for (let x = 0; x < m; ++x) {
                    const o = 3 * ((f * m + y) * m + x);
                    if (l === 0) {
                        const c = rgbOf(f, x, y);
                        for (let k = 0; k < 3; ++k) cur[o + k] = Number.isFinite(c[k]) ? c[k] : 0;
                        continue;
                    }
                    // The exact box filter: the solid-angle-weighted mean of the 2 x 2 finer texels.
                    const fm = 2 * m;
                    let w = 0;
                    const acc = [0, 0, 0];
                    for (let j = 0; j < 2; ++j)
                        for (let i = 0; i < 2; ++i) {
                            const fx = 2 * x + i, fy = 2 * y + j, wf = texelSolidAngle(fx, fy, fm);
                            const fo = 3 * ((f * fm + fy) * fm + fx);
                            for (let k = 0; k < 3; ++k) acc[k] += wf * fine[fo + k];
                            w += wf;
                        }
                    for (let k = 0; k < 3; ++k) cur[o + k] = acc[k] / w;
                }
        for (let f = 0; f < 6; ++f)
            for (let y = 0; y < m; ++y)
                for (let x = 0; x < m; ++x) {
                    const o = 3 * ((f * m + y) * m + x), q = at(lv, f, x, y);
                    for (let k = 0; k < 3; ++k) data[q + k] = cur[o + k];
                }
        // Borders: the texel across each edge, the corners the mean of their three texels.
        for (let f = 0; f < 6; ++f) {
            for (let i = 0; i < m; ++i)
                for (const [x, y] of [[-1, i], [m, i], [i, -1], [i, m]]) {
                    const [g, gx, gy] = foldBorder(f, x, y, m);
                    const q = at(lv, f, x, y), r = at(lv, g, gx, gy);
                    for (let k = 0; k < 3; ++k) data[q + k] = data[r + k];
                }
            for (const [cx, ix] of [[-1, 0], [m, m - 1]])
                for (const [cy, iy] of [[-1, 0], [m, m - 1]]) {
                    const a = at(lv, f, ix, iy), b = at(lv, f, cx, iy), c = at(lv, f, ix, cy), q = at(lv, f, cx, cy);
                    for (let k = 0; k < 3; ++k) data[q + k] = data[a + k] + ((data[b + k] - data[a + k]) + (data[c + k] - data[a + k])) / 3;
                }
        }
        fine = cur;
    });
    return { data, levels };
}

// ---- the fast filter's taps ---------------------------------------------------------------------

/// The rows of include/ibl/bake/prefilter_fast_tables.hpp: [{weight, roughness, budget, tail, bias}].
export function parseFastShapes(text) {
    const rows = [];
    const re = /\{ld_weight::(n_dot_l|g1), ([-\d.]+), (\d+), \{([-\d.]+), ([-\d.]+)\}/g;
    for (let m; (m = re.exec(text));)
        rows.push({ weight: m[1] === 'g1' ? 'g1' : 'nl', roughness: +m[2], budget: +m[3], tail: +m[4], bias: +m[5] });
    if (!rows.length) throw new Error('prefilter_fast_tables.hpp: no shape rows');
    return rows;
}

/// ibl::fast_shape: the row of the largest budget <= samples (else the smallest) nearest in roughness.
function fastShape(rows, roughness, samples, weight) {
    const r = Math.min(1, Math.max(0, Number.isFinite(roughness) ? roughness : 0));
    const mine = rows.filter((row) => row.weight === weight);
    let budget = 0, smallest = Infinity;
    for (const row of mine) {
        smallest = Math.min(smallest, row.budget);
        if (row.budget <= samples) budget = Math.max(budget, row.budget);
    }
    if (budget === 0) budget = smallest;
    let best = null;
    for (const row of mine)
        if (row.budget === budget && (!best || Math.abs(row.roughness - r) < Math.abs(best.roughness - r))) best = row;
    return best || { tail: 1, bias: 0.5 };
}

/// The GGX LD kernel at angle theta (prefilter_fast.hpp detail::fast_kernel).
function kernel(theta, r, weight) {
    const nl = Math.cos(theta);
    if (!(nl > 0)) return 0;
    const alpha = r * r, a2 = alpha * alpha, ch = Math.cos(0.5 * theta);
    const d = ch * ch * (a2 - 1) + 1;
    const D = a2 / (Math.PI * d * d);
    const w = weight === 'g1' ? 2 * nl / (nl + Math.sqrt(a2 + (1 - a2) * nl * nl)) : nl;
    const k = 0.25 * D * w;
    return Number.isFinite(k) && k > 0 ? k : 0;
}

/// Taps of one level: { taps: Float32Array (x, y, z, w per tap), info: Float32Array (n, stride,
/// face stride, offset per tap), count, factor }, the tables ibl_prefilter.glsl reads.
export function fastTaps(rows, roughness, samples, weight, trilinear, packed) {
    const r = Math.min(1, Math.max(0, Number.isFinite(roughness) ? roughness : 0));
    const n = Math.max(1, samples >>> 0);
    const shape = fastShape(rows, r, n, weight);
    const tail = Number.isFinite(shape.tail) && shape.tail > 0 ? shape.tail : 1;
    const bias4 = Math.pow(2, 2 * shape.bias);
    // The radial CDF (detail::make_fast_radial_cdf).
    const m = 4096, lo = 1e-6 * 2 * Math.atan(Math.max(r * r, 1e-3)), hi = 0.5 * Math.PI;
    const th = [0], cdf = [0];
    let pt = 0, pf = 0, acc = 0;
    for (let i = 0; i <= m; ++i) {
        const t = lo * Math.pow(hi / lo, i / m), f = kernel(t, r, weight) * Math.sin(t);
        acc += 0.5 * (f + pf) * (t - pt);
        th.push(t);
        cdf.push(acc);
        pt = t, pf = f;
    }
    for (let i = 0; i < cdf.length; ++i) cdf[i] = acc > 0 ? cdf[i] / acc : 0;
    const at = (u) => {
        let a = 0, b = cdf.length; // lower_bound
        while (a < b) { const c = (a + b) >> 1; if (cdf[c] < u) a = c + 1; else b = c; }
        if (a === 0) return 0;
        if (a === cdf.length) return th[th.length - 1];
        const d = cdf[a] - cdf[a - 1], f = d > 0 ? (u - cdf[a - 1]) / d : 0;
        return th[a - 1] + f * (th[a] - th[a - 1]);
    };
    const norm = 2 * Math.PI * acc;
    const warp = (x) => 1 - Math.pow(1 - x, tail);
    const omega0 = 4 * Math.PI / (6 * packed.levels[0].n * packed.levels[0].n), maxLod = packed.levels.length - 1;
    const lodOf = (omega) => (omega > omega0 ? Math.min(maxLod, 0.5 * Math.log2(omega / omega0)) : 0);
    const samplesOut = [];
    for (let i = 0; i < n; ++i) {
        const u0 = warp(i / n), u1 = i + 1 === n ? 1 : warp((i + 1) / n), mass = u1 - u0;
        const theta = at(warp((i + 0.5) / n)), k = kernel(theta, r, weight);
        if (!(mass > 0) || !(k > 0) || !(norm > 0)) continue;
        const phi = 2.399963229728653 * i, st = Math.sin(theta), ct = Math.cos(theta);
        samplesOut.push([Math.fround(st * Math.cos(phi)), Math.fround(st * Math.sin(phi)), Math.fround(ct), Math.fround(mass),
                         Math.fround(lodOf(mass / (k / norm) * bias4))]);
    }
    if (!samplesOut.length) samplesOut.push([0, 0, 1, 1, 0]);
    // detail::make_taps: a sample at lod l0 + f is split into taps on l0 and l0 + 1.
    const taps = [], info = [];
    const push = (s, level, w) => {
        if (!(w > 0)) return;
        const lv = packed.levels[level];
        taps.push(s[0], s[1], s[2], Math.fround(w));
        info.push(lv.n, lv.stride, lv.faceStride, lv.offset);
    };
    for (const s of samplesOut) {
        const lod = Math.min(maxLod, Math.max(0, s[4])), l0 = Math.floor(lod), f = lod - l0;
        if (!trilinear) { push(s, f < 0.5 ? l0 : l0 + 1, s[3]); continue; }
        push(s, l0, s[3] * (1 - f));
        if (f > 0) push(s, l0 + 1, s[3] * f);
    }
    let total = 0;
    for (let b = 0; b < taps.length / 4; b += 32) {
        let part = 0;
        for (let i = b; i < Math.min(b + 32, taps.length / 4); ++i) part = Math.fround(part + taps[4 * i + 3]);
        total = Math.fround(total + part);
    }
    return { taps: new Float32Array(taps), info: new Float32Array(info), count: taps.length / 4, factor: total > 0 ? Math.fround(1 / total) : 0 };
}
