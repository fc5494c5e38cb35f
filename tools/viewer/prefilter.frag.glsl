// tools/viewer/prefilter.frag.glsl — one face of one prefiltered level (ibl_prefilter.glsl): pixel
// (x, y) of the n x n RGBA32F target is texel (x, y) of face u_face (readPixels returns row y = 0
// first, the cubemap's row order): the tap set's sum plus the level's peaks (u_peak_count 0: none)
// plus the coarse tail's share of the next level, packed on u_next (u_tail_share 0: none).

uniform sampler2D u_src, u_taps, u_peaks, u_next;
uniform int u_count, u_face, u_n, u_peak_count, u_next_n;
uniform float u_factor, u_peak_a2, u_peak_b2, u_tail_m, u_tail_share;
uniform bool u_peak_g1;
out vec4 o_color;

void main() {
    int x = int(gl_FragCoord.x), y = int(gl_FragCoord.y);
    vec3 dir = ibl_cube_texel_direction(u_face, x, y, u_n);
    vec3 taps = ibl_prefilter_texel(u_src, u_taps, u_count, u_factor, dir);
    vec3 peaks = ibl_prefilter_peaks_rest(u_peaks, u_peak_count, u_peak_a2, u_peak_g1, u_peak_b2, u_tail_m, dir);
    o_color = vec4(taps + peaks + ibl_prefilter_tail(u_next, u_next_n, u_tail_share, u_face, x, y, u_n), 1.0);
}
