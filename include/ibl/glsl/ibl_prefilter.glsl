// ibl/glsl/ibl_prefilter.glsl — the prefilter's convolution (bake/sphere_convolve.hpp's cubemap
// fast path, batch/sphere_kernel.hpp) as a fragment shader: one pass per output face and level
// renders that face's n x n texels into a float target, each the normalised sum of the level's
// taps read bilinearly from the source. The taps are the C++ tables: the fast filter's
// (bake/prefilter_fast.hpp) or filtered importance sampling's, split into single-level bilinear
// taps (detail::make_taps), so a GPU re-filters a dynamic probe with the same filter the bake uses.
//
// Inputs (what tools/viewer/viewer.js uploads, from ibl::detail::pack_cube and make_taps):
//   src   RGBA32F 2-D texture: the packed source (every level's faces with their 1-texel borders,
//         detail::packed_cube), texel k of the packing at (k % width, k / width), read by texelFetch;
//   taps  RGBA32F 2-D texture of `count` x 2 texels: row 0 the tap (x, y, z, w) (tangent-space
//         direction, weight), row 1 its source level (n, n + 2, (n + 2)^2, offset of the level);
//   factor  make_taps' scale / norm (norm: the weights summed in blocks of 32, as here).
//   peaks (optional: the fast filter's peak split, bake/prefilter_peaks.hpp) RGBA32F 2-D texture
//         of `peak_count` x 2 texels, a level's merged peaks as make_peak_level builds them: row 0
//         the peak's unit direction (x, y, z, 0), row 1 its pre-scaled energy (er, eg, eb, 0); with
//         the level's a2 (alpha^2) and LD weight (g1: ld_weight::g1, else n.l). The source is then
//         the split's base (split_cube_peaks), packed. ibl_prefilter_peaks adds them exactly.
//   next (optional: the fast filter's coarse tail, prefilter_options::coarse_tail) RGBA32F 2-D
//         texture: the finished next level before its peaks (n_next x n_next faces) packed with
//         its 1-texel border as detail::pack_cube packs one level; ibl_prefilter_tail adds share
//         times its bilinear read at the texel centre to the taps, which are then those of the
//         rest kernel (make_ld_table_for with the next roughness), before the peaks are added.
//   sh (optional: the fast filter's rough levels by spherical harmonics, bake/prefilter_sh.hpp)
//         RGBA32F 2-D texture of sh_pair_count(bands) x 3 texels, one column per (l, m) pair in
//         the C++ kernels' order (m outer, l = m .. bands - 1 inner): row 0 the level's cosine
//         coefficients (sh_level::coef's R G B, then the norm's: the same level of a constant 1
//         projected as the source), row 1 the sine ones, row 2 the recurrence's constants (a_lm,
//         b_lm, sqrt((2m + 1) / (2m)), 0; sh_recurrence). ibl_prefilter_sh reconstructs the level
//         from them instead of its taps (the level then has no coarse tail); the peaks are added
//         after it as after the taps.
// Every operation is the C++ kernel's in the same order (the frame, the branch-free face selection,
// the bordered bilinear address and weights, the blocks of 32 taps), so the result equals the
// C++ within float rounding (the browser test: within half-float rounding on every level).
// Differences from the C++: the frame's sign(n.z) (ibl_make_frame, ibl_runtime.glsl) differs at
// n.z = -0 only, i.e. at texel centres on a face's middle column of odd face sizes.
// Needs ibl_common.glsl, ibl_lookup.glsl, ibl_shade.glsl and ibl_runtime.glsl first.

#ifndef IBL_GLSL_PREFILTER
#define IBL_GLSL_PREFILTER 1
#ifndef IBL_GLSL_RUNTIME
#error "ibl_prefilter.glsl needs ibl_runtime.glsl first"
#endif

// Unit direction through the centre of texel (x, y) of face `face` of an n x n level
// (env/cube_geometry.hpp cube_texel_direction).
vec3 ibl_cube_texel_direction(int face, int x, int y, int n) {
    float inv = 1.0 / float(n);
    float sc = 2.0 * ((float(x) + 0.5) * inv) - 1.0, tc = 2.0 * ((float(y) + 0.5) * inv) - 1.0;
    vec3 p = face == 0 ? vec3(1.0, -tc, -sc)
           : face == 1 ? vec3(-1.0, -tc, sc)
           : face == 2 ? vec3(sc, 1.0, tc)
           : face == 3 ? vec3(sc, -1.0, -tc)
           : face == 4 ? vec3(sc, -tc, 1.0)
                       : vec3(-sc, -tc, -1.0);
    return normalize(p);
}

// Face and (s, t) in [0, 1] of a direction: batch/sphere_kernel.hpp lane_cube_coord.
void ibl_cube_face_st(vec3 d, out int face, out float s, out float t) {
    vec3 a = abs(d);
    bool xm = a.x >= a.y && a.x >= a.z;
    bool ym = !xm && a.y >= a.z;
    float ma = xm ? a.x : (ym ? a.y : a.z);
    float major = xm ? d.x : (ym ? d.y : d.z);
    bool neg = major < 0.0;
    float sg = neg ? -1.0 : 1.0;
    float sc = xm ? -sg * d.z : (ym ? d.x : sg * d.x);
    float tc = ym ? sg * d.z : -d.y;
    face = (xm ? 0 : (ym ? 2 : 4)) + (neg ? 1 : 0);
    float half_inv = 0.5 / ma;
    s = clamp(sc * half_inv + 0.5, 0.0, 1.0);
    t = clamp(tc * half_inv + 0.5, 0.0, 1.0);
}

vec4 ibl_packed_texel(sampler2D src, int k) {
    int w = textureSize(src, 0).x;
    return texelFetch(src, ivec2(k % w, k / w), 0);
}

// The convolution of one output direction: factor * sum_i w_i B(src, level_i, F(dir) l_i).
vec3 ibl_prefilter_texel(sampler2D src, sampler2D taps, int count, float factor, vec3 dir) {
    ibl_frame fr = ibl_make_frame(dir);
    vec4 total = vec4(0.0);
    for (int b = 0; b < count; b += 32) {
        vec4 block = vec4(0.0);
        int e = min(b + 32, count);
        for (int i = b; i < e; ++i) {
            vec4 tap = texelFetch(taps, ivec2(i, 0), 0);
            vec4 lv = texelFetch(taps, ivec2(i, 1), 0);
            vec3 d = vec3(fr.t.x * tap.x + fr.b.x * tap.y + fr.n.x * tap.z,
                          fr.t.y * tap.x + fr.b.y * tap.y + fr.n.y * tap.z,
                          fr.t.z * tap.x + fr.b.z * tap.y + fr.n.z * tap.z);
            int face;
            float s, t;
            ibl_cube_face_st(d, face, s, t);
            int n = int(lv.x), st = int(lv.y), fs = int(lv.z), off = int(lv.w);
            float fx = s * lv.x + 0.5, fy = t * lv.x + 0.5; // bordered coordinates in [0.5, n + 0.5]
            int x0 = min(int(fx), n), y0 = min(int(fy), n);
            float wx = fx - float(x0), wy = fy - float(y0);
            int idx = off + face * fs + y0 * st + x0;
            vec4 p0 = ibl_packed_texel(src, idx), p1 = ibl_packed_texel(src, idx + 1);
            vec4 q0 = ibl_packed_texel(src, idx + st), q1 = ibl_packed_texel(src, idx + st + 1);
            vec4 top = p0 + wx * (p1 - p0);
            vec4 bot = q0 + wx * (q1 - q0);
            block += tap.w * (top + wy * (bot - top));
        }
        total += block;
    }
    return total.rgb * factor;
}

// The peaks of a level added back exactly (bake/prefilter_peaks.hpp detail::splat_peaks_row): sum
// over the list of E_j K(c), c = dir . d_j, cp = max(c, 0), q = (1 - cp) / 2 + a2 (1 + cp) / 2,
// K = cp / q^2 (n.l) or cp (2 / (cp + sqrt(a2 + (1 - a2) cp^2))) / q^2 (g1); 0 behind the peak.
// The C++ adds this sum to the tap set's result after it, in list order, as here; it skips the
// peaks behind a whole face row (whose terms are 0) and, with peak_split_options::cut > 0, the
// negligible ones: cut = 0 gives the sum here. peak_count 0: the tap set only.
vec3 ibl_prefilter_peaks(sampler2D peaks, int peak_count, float a2, bool g1, vec3 dir) {
    float ha2 = 0.5 * a2, one_minus_a2 = 1.0 - a2;
    vec3 acc = vec3(0.0);
    for (int j = 0; j < peak_count; ++j) {
        vec4 d = texelFetch(peaks, ivec2(j, 0), 0);
        vec4 e = texelFetch(peaks, ivec2(j, 1), 0);
        float c = dir.x * d.x + dir.y * d.y + dir.z * d.z;
        float cp = c > 0.0 ? c : 0.0;
        float q = 0.5 * (1.0 - cp) + ha2 * (1.0 + cp);
        float k;
        if (g1) {
            float g = 2.0 / (cp + sqrt(a2 + one_minus_a2 * cp * cp)); // G1 / n.l
            k = cp * g / (q * q);
        } else {
            k = cp / (q * q);
        }
        acc += e.rgb * k;
    }
    return acc;
}

// A level by spherical harmonics (bake/prefilter_sh.hpp sh_level_lanes16 and sh_level_norm): the
// normalised associated-Legendre recurrence in dir.z and Re / Im (dir.x + i dir.y)^m, per m the
// cosine and sine sums over l, then the level's value clamped at 0 over the same reconstruction of
// a constant 1 (alpha: the norm, which makes a white source exactly white), as the C++ does in float.
vec3 ibl_prefilter_sh(sampler2D sh, int bands, vec3 dir) {
    vec4 acc = vec4(0.0);
    float cr = 1.0, ci = 0.0, qmm = 0.28209479177387814;
    int p = 0;
    for (int m = 0; m < bands; ++m) {
        if (m > 0) {
            float nr = cr * dir.x - ci * dir.y, ni = cr * dir.y + ci * dir.x;
            cr = nr;
            ci = ni;
            qmm *= texelFetch(sh, ivec2(p, 2), 0).z;
        }
        vec4 sc = texelFetch(sh, ivec2(p, 0), 0) * qmm, ss = texelFetch(sh, ivec2(p, 1), 0) * qmm;
        float q1 = qmm, q2 = 0.0;
        ++p;
        for (int l = m + 1; l < bands; ++l, ++p) { // a_(m+1)m = sqrt(2m + 3), b = 0 starts it
            vec4 ab = texelFetch(sh, ivec2(p, 2), 0);
            float q = ab.x * (dir.z * q1 - ab.y * q2);
            q2 = q1;
            q1 = q;
            sc += texelFetch(sh, ivec2(p, 0), 0) * q;
            ss += texelFetch(sh, ivec2(p, 1), 0) * q;
        }
        acc += cr * sc + ci * ss;
    }
    vec3 v = max(acc.rgb, vec3(0.0));
    float norm = max(acc.a, 0.0);
    return norm > 0.0 ? v / norm : v;
}

// The projection behind those levels on the GPU (bake/prefilter_sh.hpp sh_projection): the sums
// over the n x n texels of face `face` of one level of the packed source (its n, stride, face
// stride and offset as in the taps' texture) of radiance x exact solid angle x Q_l^m(z) Re (sine:
// Im) (x + i y)^m, RGB, and in alpha the same sum for a constant 1 (the norm's). Pair (l, m) of
// `bands` as ibl_prefilter_sh's columns (the recurrence's constants computed here). A renderer
// runs it as one pass of sh_pair_count x 12 texels (a column per pair; rows: six faces, cosine then
// sine) and adds the six faces: the coefficients ibl_prefilter_sh's texture is built from (times
// k_l, and 2 for m > 0), without reading the source back. Float sums in row order: the C++ sums in
// float lanes and reduces in double, so the two agree to float rounding (the browser test: within
// 1e-5 of the largest coefficient).
float ibl_cube_texel_solid_angle(int x, int y, int n) {
    float inv = 2.0 / float(n);
    float u0 = float(x) * inv - 1.0, u1 = float(x + 1) * inv - 1.0;
    float v0 = float(y) * inv - 1.0, v1 = float(y + 1) * inv - 1.0;
    // F(u, v) = atan(u v / sqrt(u^2 + v^2 + 1)) at the four corners: the one-argument atan (the
    // denominator is at least 1). The two-argument form is the C++'s, but SwiftShader returns pi
    // for atan(-0.0, x > 0) (a corner on a face's middle line), which made one texel a face negative.
    float a = atan(u1 * v1 / sqrt(u1 * u1 + v1 * v1 + 1.0)), b = atan(u0 * v1 / sqrt(u0 * u0 + v1 * v1 + 1.0));
    float c = atan(u1 * v0 / sqrt(u1 * u1 + v0 * v0 + 1.0)), d = atan(u0 * v0 / sqrt(u0 * u0 + v0 * v0 + 1.0));
    return a - b - c + d;
}
// Q_l^m(z) of the normalised associated-Legendre recurrence (ibl_prefilter_sh's, bake/prefilter_sh.hpp).
float ibl_sh_q(int l, int m, float z) {
    float q = 0.28209479177387814;
    for (int k = 1; k <= m; ++k) q *= sqrt(float(2 * k + 1) / float(2 * k));
    float q1 = q, q2 = 0.0;
    for (int j = m + 1; j <= l; ++j) {
        float fl = float(j), fm = float(m);
        float ra = sqrt((4.0 * fl * fl - 1.0) / (fl * fl - fm * fm));
        float rb = j > m + 1 ? sqrt(((fl - 1.0) * (fl - 1.0) - fm * fm) / (4.0 * (fl - 1.0) * (fl - 1.0) - 1.0)) : 0.0;
        float qn = ra * (z * q1 - rb * q2);
        q2 = q1;
        q1 = qn;
    }
    return q1;
}
// Re (sine: Im) (x + i y)^m.
float ibl_sh_phase(vec3 d, int m, bool sine) {
    float cr = 1.0, ci = 0.0;
    for (int k = 1; k <= m; ++k) {
        float nr = cr * d.x - ci * d.y, ni = cr * d.y + ci * d.x;
        cr = nr;
        ci = ni;
    }
    return sine ? ci : cr;
}
vec4 ibl_prefilter_sh_project(sampler2D src, ivec4 level, int face, int l, int m, bool sine) {
    int n = level.x, st = level.y, fs = level.z, off = level.w;
    vec4 acc = vec4(0.0);
    for (int y = 0; y < n; ++y) {
        vec4 line = vec4(0.0);
        for (int x = 0; x < n; ++x) {
            vec3 dir = ibl_cube_texel_direction(face, x, y, n);
            float weight = ibl_cube_texel_solid_angle(x, y, n) * ibl_sh_q(l, m, dir.z) * ibl_sh_phase(dir, m, sine);
            vec3 radiance = ibl_packed_texel(src, off + face * fs + (y + 1) * st + (x + 1)).rgb;
            line += vec4(radiance * weight, weight);
        }
        acc += line;
    }
    return acc;
}

// The coarse tail (prefilter_options::coarse_tail, detail::add_coarse_tail_row): share times the
// next level (packed as above, n_next x n_next faces) read bilinearly at the centre of texel
// (x, y) of face `face` of the n x n level being filtered: cubemap::bilinear(face, s, t) with
// s = (x + 0.5) / n, t = (y + 0.5) / n, on the bordered texels. share 0: nothing is read.
vec3 ibl_prefilter_tail(sampler2D next, int n_next, float share, int face, int x, int y, int n) {
    if (!(share > 0.0)) return vec3(0.0);
    float s = (float(x) + 0.5) / float(n), t = (float(y) + 0.5) / float(n);
    float fx = s * float(n_next) + 0.5, fy = t * float(n_next) + 0.5;
    int x0 = min(int(fx), n_next), y0 = min(int(fy), n_next);
    float wx = fx - float(x0), wy = fy - float(y0);
    int st = n_next + 2;
    int idx = face * st * st + y0 * st + x0;
    vec4 p0 = ibl_packed_texel(next, idx), p1 = ibl_packed_texel(next, idx + 1);
    vec4 q0 = ibl_packed_texel(next, idx + st), q1 = ibl_packed_texel(next, idx + st + 1);
    vec4 top = p0 + wx * (p1 - p0);
    vec4 bot = q0 + wx * (q1 - q0);
    return share * (top + wy * (bot - top)).rgb;
}

#endif // IBL_GLSL_PREFILTER
