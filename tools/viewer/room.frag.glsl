// tools/viewer/room.frag.glsl — the room example (room.html): the analytic room of
// ibl/reference/analytic_room.hpp lit by two local probes. Every visible surface reflects: the
// camera ray meets a wall, reflects about it, and the reflected radiance is the probes' prefiltered
// chains read at the wall's roughness, blended by their influence boxes. The left half of the
// target reads them as distant environments (R, r); the right half parallax-corrected against the
// room's box with the distance-based roughness (ibl_local_probe.glsl). Linear RGB out.
// tests/browser/room_reference.cpp shades the same pixels in C++ by the same steps.
uniform samplerCube u_probe0, u_probe1;
uniform vec3 u_cam, u_fwd, u_right, u_up;
uniform vec2 u_tan;       // tangents of the half fields of view (x, y)
uniform vec2 u_half_size; // pixels of one half
uniform vec3 u_room_lo, u_room_hi;
uniform float u_roughness[6]; // per wall: -X, +X, floor, ceiling, -Z, +Z
uniform vec3 u_at[2], u_infl_lo[2], u_infl_hi[2];
uniform float u_fade[2];
uniform ivec4 u_priority;
uniform int u_levels;
uniform int u_half; // -1: both halves side by side (the test); 0: uncorrected only; 1: corrected only
out vec4 frag;

// Where the ray from p (inside the room) along d leaves it, and the wall (analytic_room::exit).
float room_exit(vec3 p, vec3 d, out int wall) {
    wall = -1;
    float best = 3.0e38;
    for (int k = 0; k < 3; ++k) {
        float t = 3.0e38;
        int w = -1;
        if (d[k] > 0.0) { t = (u_room_hi[k] - p[k]) / d[k]; w = 2 * k + 1; }
        else if (d[k] < 0.0) { t = (u_room_lo[k] - p[k]) / d[k]; w = 2 * k; }
        if (w >= 0 && t < best) { best = t; wall = w; }
    }
    return best;
}

vec3 probe_ld(samplerCube chain, vec3 at, ibl_probe_box proxy, vec3 p, vec3 r, float rough, bool corrected) {
    vec3 dir = r;
    float rr = rough;
    if (corrected) {
        ibl_parallax_lookup l = ibl_parallax_box(proxy, at, p, r);
        dir = l.direction;
        rr = ibl_corrected_roughness(rough, l);
    }
    return ibl_specular_lookup(chain, dir, rr, ibl_specular_textbook(u_levels, 0, u_levels));
}

void main() {
    vec2 f = gl_FragCoord.xy;
    bool corrected = u_half == 1;
    if (u_half < 0 && f.x >= u_half_size.x) {
        corrected = true;
        f.x -= u_half_size.x;
    }
    vec2 ndc = 2.0 * f / u_half_size - 1.0;
    vec3 d = normalize(u_fwd + (ndc.x * u_tan.x) * u_right + (ndc.y * u_tan.y) * u_up);
    int wall;
    float t = room_exit(u_cam, d, wall);
    vec3 p = u_cam + t * d;
    int axis = wall / 2;
    bool upper = wall - 2 * axis == 1;
    p[axis] = upper ? u_room_hi[axis] : u_room_lo[axis]; // exactly on the wall
    vec3 n = vec3(0.0);
    n[axis] = upper ? -1.0 : 1.0; // facing into the room
    vec3 r = d - 2.0 * dot(n, d) * n;
    float rough = u_roughness[wall];
    ibl_probe_box proxy = ibl_probe_box_axis_aligned(u_room_lo, u_room_hi);
    vec4 w = vec4(ibl_influence_box(ibl_probe_box_axis_aligned(u_infl_lo[0], u_infl_hi[0]), u_fade[0], p),
                  ibl_influence_box(ibl_probe_box_axis_aligned(u_infl_lo[1], u_infl_hi[1]), u_fade[1], p), 0.0, 0.0);
    vec4 c;
    ibl_blend_probe_weights4(w, u_priority, 2, c); // the fallback (black) takes what remains
    vec3 ld = c.x * probe_ld(u_probe0, u_at[0], proxy, p, r, rough, corrected);
    ld += c.y * probe_ld(u_probe1, u_at[1], proxy, p, r, rough, corrected);
    frag = vec4(ld, 1.0);
}
