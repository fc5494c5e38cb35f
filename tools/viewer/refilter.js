// tools/viewer/refilter.js — what the viewer needs to re-filter a chain on the GPU with
// include/ibl/glsl/ibl_prefilter.glsl: the source packed as the C++ kernel reads it (every level's
// faces with a 1-texel border, levels by the exact solid-angle box filter: ibl::cubemap's
// generate_mips and update_borders, ibl::detail::pack_cube) and the fast filter's taps per level
// (ibl::make_fast_ld_table with the shapes of include/ibl/bake/prefilter_fast_tables.hpp, split
// into single-level taps as ibl::detail::make_taps), and the fast filter's peak split
// (include/ibl/bake/prefilter_peaks.hpp: split_cube_peaks, merge_cube_peaks, make_peak_level): the
// brightest texels leave the packed source and each level gets its merged peak list, which
// ibl_prefilter_peaks adds back exactly. Written after the C++ (same formulas, same order), in
// double; tests/browser/run_browser_test.py --mode prefilter compares all of it with the C++.

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
/// full mip chain (power-of-two n; at most maxLevels levels: 1 packs one level with its border, as
/// the coarse tail's next level is read): { data: Float32Array (4 per texel), levels: [{n, stride,
/// faceStride, offset}] }, the layout of ibl::detail::pack_cube. With `peaks` (splitPeaks' list)
/// it packs the split's base as split_cube_peaks makes it: the mips of the source, then each
/// peak's level-0 texel scaled to the threshold and, on every coarser level, the peak's energy over
/// the covering texel's solid angle taken out (clamped at 0), the peaks in list order.
export function packSource(n, rgbOf, peaks = null, maxLevels = Infinity) {
    if (!(n >= 1) || (n & (n - 1)) !== 0) throw new Error(`re-filtering needs a power-of-two face, got ${n}`);
    const levels = [];
    let total = 0;
    for (let m = n; ; m >>= 1) {
        levels.push({ n: m, stride: m + 2, faceStride: (m + 2) * (m + 2), offset: total });
        total += 6 * (m + 2) * (m + 2);
        if (m === 1 || levels.length >= maxLevels) break;
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
        let out = cur; // what the level packs: the source's level, or the split's base
        if (peaks && peaks.length) {
            out = Float64Array.from(cur);
            for (const p of peaks) {
                const cx = p.x >> l, cy = p.y >> l, o = 3 * ((p.face * m + cy) * m + cx);
                if (l === 0) {
                    for (let k = 0; k < 3; ++k) out[o + k] = Math.fround(out[o + k] * p.scale);
                    continue;
                }
                const om = texelSolidAngle(cx, cy, m);
                for (let k = 0; k < 3; ++k) out[o + k] = Math.fround(Math.max(out[o + k] - p.energy[k] / om, 0));
            }
        }
        for (let f = 0; f < 6; ++f)
            for (let y = 0; y < m; ++y)
                for (let x = 0; x < m; ++x) {
                    const o = 3 * ((f * m + y) * m + x), q = at(lv, f, x, y);
                    for (let k = 0; k < 3; ++k) data[q + k] = out[o + k];
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

/// The radial CDF of a kernel k(theta) on the grid of roughness r (detail::make_radial_cdf_of): { th, cdf, total }.
function radialCdfOf(r, k) {
    const m = 4096, lo = 1e-6 * 2 * Math.atan(Math.max(r * r, 1e-3)), hi = 0.5 * Math.PI;
    const th = [0], cdf = [0];
    let pt = 0, pf = 0, acc = 0;
    for (let i = 0; i <= m; ++i) {
        const t = lo * Math.pow(hi / lo, i / m), kv = k(t), f = (kv > 0 ? kv : 0) * Math.sin(t);
        acc += 0.5 * (f + pf) * (t - pt);
        th.push(t);
        cdf.push(acc);
        pt = t, pf = f;
    }
    for (let i = 0; i < cdf.length; ++i) cdf[i] = acc > 0 ? cdf[i] / acc : 0;
    return { th, cdf, total: acc };
}
/// The radial CDF of the kernel at roughness r (detail::make_fast_radial_cdf).
function radialCdf(r, weight) {
    return radialCdfOf(r, (t) => kernel(t, r, weight));
}

/// The coarse tail (detail::make_fast_rest_kernel): c = the least K / K_next over the CDF's grid,
/// the rest K - c K_next's CDF, share = 1 - its integral / K's. { cdf, c, share } (c = share = 0:
/// no bound, the whole kernel).
export function restKernel(r, rn, weight) {
    const whole = radialCdf(r, weight);
    let c = Infinity;
    for (let i = 1; i < whole.th.length; ++i) {
        const k = kernel(whole.th[i], r, weight), kn = kernel(whole.th[i], rn, weight);
        if (k > 0 && kn > 0) c = Math.min(c, k / kn);
    }
    if (!Number.isFinite(c) || !(c > 0) || !(whole.total > 0)) return { cdf: whole, c: 0, share: 0 };
    const cdf = radialCdfOf(r, (t) => kernel(t, r, weight) - c * kernel(t, rn, weight));
    return { cdf, c, share: Math.min(1, Math.max(0, 1 - cdf.total / whole.total)) };
}

/// Taps of one level: { taps: Float32Array (x, y, z, w per tap), info: Float32Array (n, stride,
/// face stride, offset per tap), count, factor }, the tables ibl_prefilter.glsl reads.
export function fastTaps(rows, roughness, samples, weight, trilinear, packed, nextRoughness = -1) {
    const r = Math.min(1, Math.max(0, Number.isFinite(roughness) ? roughness : 0));
    const n = Math.max(1, samples >>> 0);
    const shape = fastShape(rows, r, n, weight);
    const tail = Number.isFinite(shape.tail) && shape.tail > 0 ? shape.tail : 1;
    const bias4 = Math.pow(2, 2 * shape.bias);
    // With a next roughness: the coarse tail's rest kernel, scale 1 - share (make_fast_ld_table).
    const rn = Number.isFinite(nextRoughness) && nextRoughness >= 0 ? Math.min(1, nextRoughness) : -1;
    const rest = rn >= 0 ? restKernel(r, rn, weight) : { cdf: radialCdf(r, weight), c: 0, share: 0 };
    const { th, cdf, total: acc } = rest.cdf;
    const kern = (t) => { const k = kernel(t, r, weight); return rest.c > 0 ? k - rest.c * kernel(t, rn, weight) : k; };
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
        const theta = at(warp((i + 0.5) / n)), k = kern(theta);
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
    const scale = Math.fround(1 - rest.share);
    return { taps: new Float32Array(taps), info: new Float32Array(info), count: taps.length / 4,
             factor: total > 0 ? Math.fround(scale / total) : 0, tail_share: Math.fround(rest.share), tail_c: rest.c };
}

/// prefilter_options::mid_tail's defaults (the C++ prefilter's; bake/prefilter_fast.hpp,
/// "Intermediate coarse tail").
export const midTailDefaults = { enabled: true, maxRoughness: 0.3, position: 0.1, own: 0.375, mid: 1.0, minTexels: 3.0, minOwnSamples: 16 };

/// The intermediate coarse tail of a level (detail::prefilter_mid_roughness, prefilter_mid_own_samples,
/// prefilter_mid_samples): a level at roughness r filtered with `samples` whose coarse tail would
/// read the next level (roughness rn >= 0, face nextFace) reads it instead from an intermediate
/// level at rm = r + position (rn - r) on a face of nextFace, filtered with `mid` samples and its
/// own coarse tail from the next level, no peaks, and spends `own` samples on the rest of its
/// kernel. Returns { roughness: rm, own, mid } or null where the level reads the next one directly.
export function midTail(r, rn, samples, nextFace, opt = midTailDefaults) {
    if (!opt.enabled || !(opt.position > 0) || !(opt.position < 1) || !(opt.own > 0) || !(opt.mid > 0)) return null;
    if (!(rn >= 0)) return null;
    r = Math.min(1, Math.max(0, Number.isFinite(r) ? r : 0));
    if (!(r <= opt.maxRoughness) || !(rn > r)) return null;
    const own = Math.max(1, Math.round(Math.min(1, opt.own) * samples));
    if (own < opt.minOwnSamples) return null;
    const rm = r + opt.position * (rn - r);
    // the intermediate face resolves its kernel: a texel at the face centre is 2 / face radians
    const face = Math.max(1, nextFace), minTexels = Number.isFinite(opt.minTexels) ? opt.minTexels : 3;
    if (!(ggxLdFwhm(rm) >= minTexels * 2 / face)) return null;
    const mid = Math.max(1, Math.round(Math.min(opt.mid * Math.max(samples, 1), 1 << 24)));
    return { roughness: rm, own, mid };
}

// ---- the peak split (include/ibl/bake/prefilter_peaks.hpp) ----------------------------------------

/// peak_split_options' defaults (the C++ prefilter's; its row cut has no GPU counterpart: the GPU
/// adds every peak of the list, what the C++ adds with cut = 0).
export const peakDefaults = { ratio: 16, maxPeaks: 1024, footprint: 6, maxMergeAngle: 1 / 16, maxLevelPeaks: 128, maxLevelSteps: 2 };

const luminance = (c) => 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];

/// Unit direction through the centre of texel (x, y) of an n x n face, rounded to float.
function texelDirection(face, x, y, n) {
    const p = facePoint(face, 2 * ((x + 0.5) / n) - 1, 2 * ((y + 0.5) / n) - 1), l = Math.hypot(p[0], p[1], p[2]);
    return p.map((v) => Math.fround(v / l));
}

/// split_cube_peaks on level 0 (six faces of n x n texels, `rgbOf(face, x, y)` -> [r, g, b]): the
/// threshold T = max(ratio x the solid-angle mean luminance, the (maxPeaks + 1)-th brightest
/// luminance) and the level-0 peaks above it, in face, row, column order: { peaks: [{ face, x, y,
/// dir, energy (Omega x the radiance above T), weight (the luminance energy), scale (T / luminance:
/// the base texel's factor) }], mean, threshold }. No texel above T: no peaks (the source is packed as is).
export function splitPeaks(n, rgbOf, opt = peakDefaults) {
    const count = 6 * n * n, lum = new Float64Array(count), rgb = new Float64Array(3 * count);
    let acc = 0;
    for (let f = 0; f < 6; ++f)
        for (let y = 0; y < n; ++y)
            for (let x = 0; x < n; ++x) {
                const i = (f * n + y) * n + x, c = rgbOf(f, x, y);
                for (let k = 0; k < 3; ++k) rgb[3 * i + k] = c[k];
                const l = Math.fround(luminance(c));
                lum[i] = Number.isFinite(l) && l > 0 ? l : 0;
                acc += lum[i] * texelSolidAngle(x, y, n);
            }
    const mean = acc / (4 * Math.PI);
    let t = Number.isFinite(opt.ratio) && opt.ratio > 0 ? opt.ratio * mean : 0;
    let above = 0;
    for (const l of lum) above += l > t ? 1 : 0;
    if (above > opt.maxPeaks) { // the threshold that keeps at most maxPeaks texels above it
        const sorted = Float64Array.from(lum).sort();
        t = Math.max(t, sorted[count - 1 - opt.maxPeaks]);
    }
    const peaks = [];
    if (!(t > 0)) return { peaks, mean, threshold: t };
    for (let f = 0; f < 6; ++f)
        for (let y = 0; y < n; ++y)
            for (let x = 0; x < n; ++x) {
                const i = (f * n + y) * n + x, l = lum[i];
                if (!(l > t)) continue;
                const om = texelSolidAngle(x, y, n), e = (1 - t / l) * om;
                peaks.push({ face: f, x, y, dir: texelDirection(f, x, y, n), energy: [0, 1, 2].map((k) => rgb[3 * i + k] * e),
                             weight: (l - t) * om, scale: t / l });
            }
    return { peaks, mean, threshold: t };
}

/// merge_cube_peaks: the peaks merged into the texels of mip `mip` (summed energy at the
/// luminance-energy centroid), in face, row, column order of the merged texels.
function mergePeaks(peaks, mip) {
    if (mip <= 0) return peaks;
    const at = new Map();
    for (const p of peaks) {
        const key = [p.face, p.y >> mip, p.x >> mip];
        const id = key.join(',');
        let q = at.get(id);
        if (!q) at.set(id, (q = { key, face: p.face, x: p.x >> mip, y: p.y >> mip, energy: [0, 0, 0], weight: 0, c: [0, 0, 0] }));
        for (let k = 0; k < 3; ++k) q.energy[k] += p.energy[k], q.c[k] += p.weight * p.dir[k];
        q.weight += p.weight;
    }
    const out = [...at.values()].sort((a, b) => a.key[0] - b.key[0] || a.key[1] - b.key[1] || a.key[2] - b.key[2]);
    for (const q of out) {
        const len = Math.hypot(q.c[0], q.c[1], q.c[2]);
        q.dir = len > 0 ? q.c.map((v) => Math.fround(v / len)) : [0, 0, 1];
    }
    return out;
}

/// ggx_ld_fwhm: the LD kernel's full width at half maximum at roughness r (radians, at most pi).
function ggxLdFwhm(r) {
    const a = Math.max(Math.min(1, Math.max(0, r)) ** 2, 1e-4), a2 = a * a;
    if (a2 >= 1) return Math.PI;
    const omc = 2 * (Math.sqrt(2) - 1) * a2 / (1 - a2);
    return Math.min(Math.PI, 2 * Math.acos(Math.max(-1, 1 - omc)));
}

/// peak_merge_mip: the coarsest mip m <= maxMip whose face-centre texel, 2 / (n0 >> m) radians, is
/// at most min(fwhm / footprint, maxAngle).
function peakMergeMip(r, n0, maxMip, footprint, maxAngle) {
    const want = Math.min(ggxLdFwhm(r) / Math.max(footprint, 1), maxAngle);
    let m = 0;
    while (m < maxMip && (n0 >> (m + 1)) >= 1 && 2 / (n0 >> (m + 1)) <= want) ++m;
    return m;
}

/// make_peak_level: a level's peaks for ibl_prefilter_peaks (the split's peaks of an n0-texel level 0
/// with `sourceLevels` mips, merged at peakMergeMip, a mip coarser while above maxLevelPeaks (maxLevelSteps times at most), energies pre-scaled by alpha^2 / (4 pi
/// integral K)): { peak_count, peaks: Float32Array (x, y, z, er, eg, eb per peak), a2, g1 }.
export function makePeakLevel(peaks, n0, sourceLevels, roughness, weight, opt = peakDefaults) {
    const none = { peak_count: 0, peaks: new Float32Array(0), a2: 0, g1: false };
    if (!peaks.length) return none;
    const r = Math.min(1, Math.max(0, Number.isFinite(roughness) ? roughness : 0));
    const a = Math.max(r * r, 1e-4), a2 = a * a;
    const norm = 2 * Math.PI * radialCdf(r, weight).total;
    if (!(norm > 0)) return none;
    const scale = a2 / (4 * Math.PI * norm);
    // More than maxLevelPeaks merged peaks: merged a mip coarser, maxLevelSteps times at most (a
    // texel at most maxMergeAngle).
    let mip = peakMergeMip(r, n0, sourceLevels - 1, opt.footprint, opt.maxMergeAngle);
    let merged = mergePeaks(peaks, mip);
    const steps = opt.maxLevelSteps ?? 1;
    for (let step = 0; step < steps && opt.maxLevelPeaks > 0 && merged.length > opt.maxLevelPeaks && mip < sourceLevels - 1 &&
         (n0 >> (mip + 1)) >= 1 && 2 / (n0 >> (mip + 1)) <= opt.maxMergeAngle; ++step)
        merged = mergePeaks(peaks, ++mip);
    const out = new Float32Array(6 * merged.length);
    merged.forEach((p, j) => {
        out.set(p.dir, 6 * j);
        for (let k = 0; k < 3; ++k) out[6 * j + 3 + k] = p.energy[k] * scale;
    });
    return { peak_count: merged.length, peaks: out, a2: Math.fround(a2), g1: weight === 'g1' };
}

// ---- the rough levels by spherical harmonics (include/ibl/bake/prefilter_sh.hpp) ---------------

/// sh_rough_options' defaults (the C++ prefilter's).
export const shDefaults = { maxBands: 24, tolerance: 5e-4 };

/// The n-point Gauss-Legendre rule on [-1, 1] (core/gauss_legendre.hpp make_gauss_legendre_symmetric).
function gaussLegendre(n) {
    const x = new Float64Array(n), w = new Float64Array(n);
    const legendre = (t) => { // P_n(t) and its derivative
        let p0 = 1, p1 = t;
        for (let k = 2; k <= n; ++k) { const p2 = ((2 * k - 1) * t * p1 - (k - 1) * p0) / k; p0 = p1; p1 = p2; }
        return [n === 0 ? 1 : p1, n * (t * p1 - p0) / (t * t - 1)];
    };
    for (let i = 0; i < (n + 1) >> 1; ++i) {
        let t = Math.cos(Math.PI * (i + 0.75) / (n + 0.5));
        for (let it = 0; it < 100; ++it) {
            const [p, dp] = legendre(t), dt = p / dp;
            t -= dt;
            if (Math.abs(dt) <= 4 * Number.EPSILON) break;
        }
        const dp = legendre(t)[1];
        x[n - 1 - i] = t, x[i] = -t;
        w[i] = w[n - 1 - i] = 2 / ((1 - t) * (1 + t) * dp * dp);
    }
    if (n % 2 === 1) x[n >> 1] = 0;
    return { x, w };
}

/// k_l, l < count, of the LD kernel normalised to k_0 = 1 (detail::zonal_band_factors: 24-node
/// Gauss-Legendre on panels in theta growing by 1.4 from a fiftieth of the lobe's scale to pi / 2).
export function bandFactors(roughness, weight, count = 97) {
    const r = Math.min(1, Math.max(0, Number.isFinite(roughness) ? roughness : 0));
    const k = new Float64Array(Math.max(count, 1)), gl = gaussLegendre(24), halfPi = 0.5 * Math.PI;
    const s = Math.max(1e-4, 2 * Math.atan(Math.max(r * r, 1e-3)));
    const edges = [0];
    for (let t = 0.02 * s; t < halfPi; t *= 1.4) edges.push(t);
    edges.push(halfPi);
    for (let e = 0; e + 1 < edges.length; ++e) {
        const a = edges[e], b = edges[e + 1];
        for (let i = 0; i < gl.x.length; ++i) {
            const t = 0.5 * (a + b) + 0.5 * (b - a) * gl.x[i];
            const f = kernel(t, r, weight) * Math.sin(t) * 0.5 * (b - a) * gl.w[i], mu = Math.cos(t);
            let p0 = 1, p1 = mu;
            for (let l = 0; l < k.length; ++l) {
                k[l] += f * p0;
                const p2 = ((2 * l + 3) * mu * p1 - (l + 1) * p0) / (l + 2);
                p0 = p1, p1 = p2;
            }
        }
    }
    const k0 = k[0];
    return k.map((v) => (k0 > 0 ? v / k0 : 0));
}

/// The bands a level of roughness r needs (detail::sh_rough_bands: the fewest B whose truncation
/// error on band powers (l + 1)^-2 is at most the tolerance), or 0 when more than maxBands.
export function shBands(roughness, weight, opt = shDefaults) {
    const k = bandFactors(roughness, weight), tail = new Float64Array(k.length + 1);
    for (let l = k.length; l-- > 0;) tail[l] = tail[l + 1] + (2 * l + 1) * k[l] * k[l] / ((l + 1) * (l + 1));
    for (let b = 1; b <= Math.min(opt.maxBands, 32); ++b) if (Math.sqrt(tail[b] / tail[0]) <= opt.tolerance) return b;
    return 0;
}

/// The packed level the projection for B bands reads (detail::sh_projection_level): the finest
/// whose face is at most max(16, 2 B), else the coarsest.
export function shProjectionLevel(packed, bands) {
    const cap = Math.max(16, 2 * bands);
    for (const l of packed.levels) if (l.n <= cap) return l;
    return packed.levels[packed.levels.length - 1];
}

/// Index of pair (l, m) in the kernels' order for B bands (m outer, l = m .. B - 1 inner).
const pairIndex = (B, l, m) => m * B - (m * (m - 1)) / 2 + (l - m);

/// The projection of packSource's packing onto B bands (detail::sh_projection on the level
/// sh_projection_level picks: the finest whose face is at most max(16, 2 B)): per pair the cosine
/// and sine sums of R G B over the texels (radiance x exact solid angle x Q_l^m Re / Im (x + i y)^m),
/// and the same of a constant 1 (the norm's). In double. { bands, face, coef, unit } (6 per pair).
export function shProject(packed, bands) {
    const lv = shProjectionLevel(packed, bands);
    const n = lv.n, pairs = (bands * (bands + 1)) / 2;
    const coef = new Float64Array(6 * pairs), unit = new Float64Array(6 * pairs);
    const mm = Array.from({ length: bands }, (_, m) => (m > 0 ? Math.sqrt((2 * m + 1) / (2 * m)) : 1));
    // the recurrence's a_lm, b_lm at l * bands + m (l > m; b = 0 at l = m + 1)
    const ra = new Float64Array(bands * bands), rb = new Float64Array(bands * bands);
    for (let m = 0; m < bands; ++m)
        for (let l = m + 1; l < bands; ++l) {
            ra[l * bands + m] = Math.sqrt((4 * l * l - 1) / (l * l - m * m));
            rb[l * bands + m] = l > m + 1 ? Math.sqrt(((l - 1) * (l - 1) - m * m) / (4 * (l - 1) * (l - 1) - 1)) : 0;
        }
    const q = new Float64Array(bands);
    for (let f = 0; f < 6; ++f)
        for (let y = 0; y < n; ++y)
            for (let x = 0; x < n; ++x) {
                const d = facePoint(f, 2 * ((x + 0.5) / n) - 1, 2 * ((y + 0.5) / n) - 1), len = Math.hypot(d[0], d[1], d[2]);
                const dx = d[0] / len, dy = d[1] / len, dz = d[2] / len, om = texelSolidAngle(x, y, n);
                const at = 4 * (lv.offset + f * lv.faceStride + (y + 1) * lv.stride + (x + 1));
                const w = [om * packed.data[at], om * packed.data[at + 1], om * packed.data[at + 2]];
                let cr = 1, ci = 0, qmm = 0.28209479177387814;
                for (let m = 0; m < bands; ++m) {
                    if (m > 0) {
                        const nr = cr * dx - ci * dy, ni = cr * dy + ci * dx;
                        cr = nr, ci = ni, qmm *= mm[m];
                    }
                    q[m] = qmm;
                    for (let l = m + 1; l < bands; ++l)
                        q[l] = ra[l * bands + m] * (dz * q[l - 1] - (l > m + 1 ? rb[l * bands + m] * q[l - 2] : 0));
                    for (let l = m; l < bands; ++l) {
                        const p = 6 * pairIndex(bands, l, m), c = q[l] * cr, s = q[l] * ci;
                        for (let ch = 0; ch < 3; ++ch) coef[p + ch] += c * w[ch], coef[p + 3 + ch] += s * w[ch];
                        unit[p] += c * om, unit[p + 3] += s * om;
                    }
                }
            }
    for (let p = 0; p < pairs; ++p) unit[6 * p + 1] = unit[6 * p + 2] = unit[6 * p], unit[6 * p + 4] = unit[6 * p + 5] = unit[6 * p + 3];
    return { bands, face: n, coef, unit };
}

/// A level's texture for ibl_prefilter_sh (sh_pair_count(B) x 3 texels, row by row): its B bands'
/// k_l (times 2 for m > 0: the basis's sqrt(2) in the projection and in the reconstruction) times
/// the projection's cosine and sine sums (R G B, the norm's in alpha), then the recurrence's
/// constants (a_lm, b_lm, sqrt((2m + 1) / (2m)), 0). { sh_bands, sh } (sh_bands 0: the level keeps its taps).
export function shLevel(proj, roughness, weight, bands) {
    if (!(bands > 0) || !proj || proj.bands < bands) return { sh_bands: 0, sh: new Float32Array(0) };
    const k = bandFactors(roughness, weight), pairs = (bands * (bands + 1)) / 2, tex = new Float32Array(12 * pairs);
    let p = 0;
    for (let m = 0; m < bands; ++m)
        for (let l = m; l < bands; ++l, ++p) {
            const g = k[l] * (m > 0 ? 2 : 1), pp = 6 * pairIndex(proj.bands, l, m);
            for (let c = 0; c < 3; ++c) {
                tex[4 * p + c] = g * proj.coef[pp + c];
                tex[4 * (pairs + p) + c] = g * proj.coef[pp + 3 + c];
            }
            tex[4 * p + 3] = g * proj.unit[pp];
            tex[4 * (pairs + p) + 3] = g * proj.unit[pp + 3];
            const L = l, M = m, r = 4 * (2 * pairs + p);
            tex[r] = l > m ? Math.sqrt((4 * L * L - 1) / (L * L - M * M)) : 1;
            tex[r + 1] = l > m ? Math.sqrt(((L - 1) * (L - 1) - M * M) / (4 * (L - 1) * (L - 1) - 1)) : 0;
            tex[r + 2] = m > 0 ? Math.sqrt((2 * m + 1) / (2 * m)) : 1;
        }
    return { sh_bands: bands, sh: tex };
}
