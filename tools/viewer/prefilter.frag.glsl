// tools/viewer/prefilter.frag.glsl — one face of one prefiltered level (ibl_prefilter.glsl): pixel
// (x, y) of the n x n RGBA32F target is texel (x, y) of face u_face (readPixels returns row y = 0
// first, the cubemap's row order): the tap set's sum plus the level's peaks (u_peak_count 0: none).

uniform sampler2D u_src, u_taps, u_peaks;
uniform int u_count, u_face, u_n, u_peak_count;
uniform float u_factor, u_peak_a2;
uniform bool u_peak_g1;
out vec4 o_color;

void main() {
    vec3 dir = ibl_cube_texel_direction(u_face, int(gl_FragCoord.x), int(gl_FragCoord.y), u_n);
    vec3 taps = ibl_prefilter_texel(u_src, u_taps, u_count, u_factor, dir);
    o_color = vec4(taps + ibl_prefilter_peaks(u_peaks, u_peak_count, u_peak_a2, u_peak_g1, dir), 1.0);
}
