// tools/viewer/prefilter.frag.glsl — one face of one prefiltered level (ibl_prefilter.glsl): pixel
// (x, y) of the n x n RGBA32F target is texel (x, y) of face u_face (readPixels returns row y = 0
// first, the cubemap's row order): the tap set's sum plus the coarse tail's share of the next
// level, packed on u_next (u_tail_share 0: none), or with u_sh_bands > 0 the level reconstructed from
// its spherical-harmonic coefficients on u_sh instead, plus the level's peaks (u_peak_count 0: none).
// The second output is the texel before its peaks: what the coarse tail of the level before reads.

uniform sampler2D u_src, u_taps, u_peaks, u_next, u_sh;
uniform int u_count, u_face, u_n, u_peak_count, u_next_n, u_sh_bands;
uniform float u_factor, u_peak_a2, u_tail_share;
uniform bool u_peak_g1;
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_before_peaks;

void main() {
    int x = int(gl_FragCoord.x), y = int(gl_FragCoord.y);
    vec3 dir = ibl_cube_texel_direction(u_face, x, y, u_n);
    vec3 base = u_sh_bands > 0 ? ibl_prefilter_sh(u_sh, u_sh_bands, dir)
                               : ibl_prefilter_texel(u_src, u_taps, u_count, u_factor, dir) +
                                     ibl_prefilter_tail(u_next, u_next_n, u_tail_share, u_face, x, y, u_n);
    o_before_peaks = vec4(base, 1.0);
    o_color = vec4(base + ibl_prefilter_peaks(u_peaks, u_peak_count, u_peak_a2, u_peak_g1, dir), 1.0);
}
