// ibl_local_probe.glsl — local reflection probes (GLSL ES 3.00 / 4.50): the GLSL mirror of
// ibl/runtime/local_probe.hpp (its header comment derives everything): ray-proxy exits for boxes
// (axis-aligned or oriented) and spheres, the parallax-corrected lookup direction, the
// distance-based roughness (with the proxy's slopes at the hit: the default), influence weights and
// the priority blend of up to four probes.
// Needs nothing else; the C++ and GLSL answers agree within float rounding (numeric grid rows
// "local probe: parallax" and "local probe: roughness, influence, blend" of the browser test).

#ifndef IBL_GLSL_LOCAL_PROBE
#define IBL_GLSL_LOCAL_PROBE 1

struct ibl_probe_box {
    vec3 center;
    vec3 half_extent;
    vec3 axis0, axis1, axis2; // orthonormal world directions of the box's x, y, z
};

ibl_probe_box ibl_probe_box_axis_aligned(vec3 lo, vec3 hi) {
    return ibl_probe_box((lo + hi) * 0.5, (hi - lo) * 0.5, vec3(1.0, 0.0, 0.0), vec3(0.0, 1.0, 0.0), vec3(0.0, 0.0, 1.0));
}

vec3 ibl_probe_box_local(ibl_probe_box b, vec3 v) { return vec3(dot(v, b.axis0), dot(v, b.axis1), dot(v, b.axis2)); }

// Distance along normalize(r) from p to where the ray leaves the box; -1 without such an exit.
float ibl_proxy_exit_box(ibl_probe_box b, vec3 p, vec3 r) {
    float len2 = dot(r, r);
    if (!(len2 > 0.0)) return -1.0;
    vec3 o = ibl_probe_box_local(b, p - b.center), d = ibl_probe_box_local(b, r * inversesqrt(len2));
    float t_near = -3.0e38, t_far = 3.0e38;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0) {
            if (abs(o[k]) > b.half_extent[k]) return -1.0;
            continue;
        }
        float inv = 1.0 / d[k];
        float a = (-b.half_extent[k] - o[k]) * inv, c = (b.half_extent[k] - o[k]) * inv;
        t_near = max(t_near, min(a, c));
        t_far = min(t_far, max(a, c));
    }
    return (t_near <= t_far && t_far > 0.0) ? t_far : -1.0;
}

float ibl_proxy_exit_sphere(vec3 center, float radius, vec3 p, vec3 r) {
    float len2 = dot(r, r);
    if (!(len2 > 0.0)) return -1.0;
    vec3 ru = r * inversesqrt(len2), o = p - center;
    float b = dot(o, ru), c = dot(o, o) - radius * radius, disc = b * b - c;
    if (!(disc >= 0.0)) return -1.0;
    float t_far = -b + sqrt(disc);
    return t_far > 0.0 ? t_far : -1.0;
}

struct ibl_parallax_lookup {
    vec3 direction; // where to read the probe captured at c
    float d_shading; // from p to the hit (0 without one)
    float d_probe;   // from c to the hit (0 without one)
    float cos_shading; // |R.n| with n the proxy's normal at the hit (1 without one)
    float cos_probe;   // |direction.n| (1 without one)
};

// The lookup for the exit distance t along normalize(r) from p (t <= 0: no correction, r itself);
// n is the proxy's unit normal at the hit p + t normalize(r) (ibl_proxy_normal_box / _sphere).
ibl_parallax_lookup ibl_parallax_from_exit(vec3 c, vec3 p, vec3 r, float t, vec3 n) {
    float len2 = dot(r, r);
    if (!(len2 > 0.0)) return ibl_parallax_lookup(r, 0.0, 0.0, 1.0, 1.0);
    vec3 ru = r * inversesqrt(len2);
    if (!(t > 0.0)) return ibl_parallax_lookup(ru, 0.0, 0.0, 1.0, 1.0);
    vec3 d = (p - c) + t * ru;
    float len = length(d);
    if (!(len > 0.0)) return ibl_parallax_lookup(ru, 0.0, 0.0, 1.0, 1.0);
    vec3 u = d / len;
    return ibl_parallax_lookup(u, t, len, abs(dot(ru, n)), abs(dot(u, n)));
}

// The proxies' unit outward normals at a point x on them (the box's face x is nearest to).
vec3 ibl_proxy_normal_box(ibl_probe_box b, vec3 x) {
    vec3 q = ibl_probe_box_local(b, x - b.center);
    int k = 0;
    float best = -1.0;
    for (int i = 0; i < 3; ++i) {
        float e = b.half_extent[i] > 0.0 ? abs(q[i]) / b.half_extent[i] : 3.0e38;
        if (e > best) {
            best = e;
            k = i;
        }
    }
    vec3 a = k == 0 ? b.axis0 : (k == 1 ? b.axis1 : b.axis2);
    return q[k] < 0.0 ? -a : a;
}

vec3 ibl_proxy_normal_sphere(vec3 center, vec3 x) {
    vec3 o = x - center;
    float len2 = dot(o, o);
    return len2 > 0.0 ? o * inversesqrt(len2) : vec3(0.0, 0.0, 1.0);
}

ibl_parallax_lookup ibl_parallax_box(ibl_probe_box b, vec3 c, vec3 p, vec3 r) {
    float t = ibl_proxy_exit_box(b, p, r);
    vec3 ru = dot(r, r) > 0.0 ? r * inversesqrt(dot(r, r)) : r;
    return ibl_parallax_from_exit(c, p, r, t, ibl_proxy_normal_box(b, p + max(t, 0.0) * ru));
}

ibl_parallax_lookup ibl_parallax_sphere(vec3 center, float radius, vec3 c, vec3 p, vec3 r) {
    float t = ibl_proxy_exit_sphere(center, radius, p, r);
    vec3 ru = dot(r, r) > 0.0 ? r * inversesqrt(dot(r, r)) : r;
    return ibl_parallax_from_exit(c, p, r, t, ibl_proxy_normal_sphere(center, p + max(t, 0.0) * ru));
}

// Distance-based roughness: r' = sqrt(clamp(r^2 d_shading / d_probe, 0, 1)); r without a hit.
float ibl_corrected_roughness(float roughness, float d_shading, float d_probe) {
    float r = clamp(roughness, 0.0, 1.0);
    if (!(d_shading > 0.0) || !(d_probe > 0.0)) return r;
    return sqrt(clamp(r * r * (d_shading / d_probe), 0.0, 1.0));
}

// The same on oblique walls (the default): r' = sqrt(clamp(r^2 (d_shading / d_probe)
// sqrt(cos_probe / cos_shading), 0, 1)), the lookup map's solid-angle scale (local_probe.hpp).
float ibl_corrected_roughness(float roughness, float d_shading, float d_probe, float cos_shading, float cos_probe) {
    float r = clamp(roughness, 0.0, 1.0);
    if (!(d_shading > 0.0) || !(d_probe > 0.0)) return r;
    float cs = clamp(cos_shading, 0.0, 1.0), cp = clamp(cos_probe, 0.0, 1.0);
    if (!(cs > 0.0) && !(cp > 0.0)) return ibl_corrected_roughness(roughness, d_shading, d_probe);
    if (!(cs > 0.0)) return r > 0.0 ? 1.0 : 0.0;
    return sqrt(clamp(r * r * (d_shading / d_probe) * sqrt(cp / cs), 0.0, 1.0));
}

float ibl_corrected_roughness(float roughness, ibl_parallax_lookup l) {
    return ibl_corrected_roughness(roughness, l.d_shading, l.d_probe, l.cos_shading, l.cos_probe);
}

// The lobe split (local_probe.hpp): IBL_PARALLAX_SPLIT_TAPS sub-lobes of roughness r / sqrt 2, weight
// 1 / 5 each, one along R and four on a ring at 2 atan(r^2 / 2) around it, each corrected on its
// own. Tap i's reflection direction (r unit), then tap i's lookup as (direction, roughness); the
// caller sums 0.2 x lookup over i = 0..4.
#define IBL_PARALLAX_SPLIT_TAPS 5
vec3 ibl_parallax_split_direction(vec3 r, float roughness, int i) {
    if (i <= 0) return r;
    float rr = clamp(roughness, 0.0, 1.0), q = 0.5 * rr * rr, q2 = q * q;
    float ct = (1.0 - q2) / (1.0 + q2), st = 2.0 * q / (1.0 + q2);
    float sg = r.z >= 0.0 ? 1.0 : -1.0, a = -1.0 / (sg + r.z), b = r.x * r.y * a;
    vec3 t = vec3(1.0 + sg * r.x * r.x * a, sg * b, -sg * r.x), bt = vec3(b, sg + r.y * r.y * a, -r.y);
    vec3 side = i == 1 ? t : (i == 2 ? bt : (i == 3 ? -t : -bt));
    return ct * r + st * side;
}

vec4 ibl_parallax_split_tap_box(ibl_probe_box b, vec3 c, vec3 p, vec3 r, float roughness, int i) {
    float len2 = dot(r, r);
    if (!(len2 > 0.0)) return vec4(r, clamp(roughness, 0.0, 1.0));
    float rr = clamp(roughness, 0.0, 1.0);
    ibl_parallax_lookup l = ibl_parallax_box(b, c, p, ibl_parallax_split_direction(r * inversesqrt(len2), rr, i));
    return vec4(l.direction, ibl_corrected_roughness(rr * sqrt(0.5), l));
}

vec4 ibl_parallax_split_tap_sphere(vec3 center, float radius, vec3 c, vec3 p, vec3 r, float roughness, int i) {
    float len2 = dot(r, r);
    if (!(len2 > 0.0)) return vec4(r, clamp(roughness, 0.0, 1.0));
    float rr = clamp(roughness, 0.0, 1.0);
    ibl_parallax_lookup l = ibl_parallax_sphere(center, radius, c, p, ibl_parallax_split_direction(r * inversesqrt(len2), rr, i));
    return vec4(l.direction, ibl_corrected_roughness(rr * sqrt(0.5), l));
}

// Influence weights: distance to the boundary inside the volume over the fade width, in [0, 1].
float ibl_influence_box(ibl_probe_box b, float fade, vec3 p) {
    vec3 d = b.half_extent - abs(ibl_probe_box_local(b, p - b.center));
    return clamp(min(d.x, min(d.y, d.z)) / max(fade, 1.17549435e-38), 0.0, 1.0);
}

float ibl_influence_sphere(vec3 center, float radius, float fade, vec3 p) {
    return clamp((radius - length(p - center)) / max(fade, 1.17549435e-38), 0.0, 1.0);
}

// The priority blend of the first n (<= 4) probes: contributions in `contrib`, the distant
// environment's share returned; higher priority first, equal priorities share by weight.
float ibl_blend_probe_weights4(vec4 weights, ivec4 priority, int n, out vec4 contrib) {
    contrib = vec4(0.0);
    float remaining = 1.0;
    bool have_prev = false;
    int prev = 0;
    for (int pass = 0; pass < 4; ++pass) {
        bool found = false;
        int level = 0;
        for (int i = 0; i < 4; ++i)
            if (i < n && (!have_prev || priority[i] < prev) && (!found || priority[i] > level)) {
                level = priority[i];
                found = true;
            }
        if (!found) break;
        float sum = 0.0;
        for (int i = 0; i < 4; ++i)
            if (i < n && priority[i] == level) sum += clamp(weights[i], 0.0, 1.0);
        float scale = remaining / max(sum, 1.0);
        float used = 0.0;
        for (int i = 0; i < 4; ++i)
            if (i < n && priority[i] == level) {
                contrib[i] = clamp(weights[i], 0.0, 1.0) * scale;
                used += contrib[i];
            }
        remaining = max(remaining - used, 0.0);
        have_prev = true;
        prev = level;
    }
    return remaining;
}

#endif // IBL_GLSL_LOCAL_PROBE
