// tools/viewer/ktx2.js — a small reader of the KTX 2.0 cubemaps ibl-bake writes
// (tools/ibl-bake/io/ktx2.hpp lists every field): header, level index, level data.
// The data format descriptor is not needed: vkFormat says everything for ibl-bake's formats.
// Returns typed arrays that WebGL2 uploads as they are (no conversion of the stored bits): the
// per-texel formats for texImage2D, the block formats (BC6H, ASTC HDR) as the bytes of their
// 16-byte blocks for compressedTexImage2D. Zstandard-supercompressed files (--ktx2-zstd N) are
// refused with a message: the viewer has no build step to bring a Zstandard decoder.

const IDENTIFIER = [0xab, 0x4b, 0x54, 0x58, 0x20, 0x32, 0x30, 0xbb, 0x0d, 0x0a, 0x1a, 0x0a];

// vkFormat -> bytes per texel, typed array, and the WebGL2 (internalformat, format, type) names;
// the block formats: block size in texels, 16 bytes per block, and the WebGL extension (with the
// name of its internalformat constant) that uploads them.
export const KTX2_FORMATS = {
    97: { name: 'R16G16B16A16_SFLOAT', bytes: 8, array: Uint16Array, per: 4, gl: ['RGBA16F', 'RGBA', 'HALF_FLOAT'] },
    109: { name: 'R32G32B32A32_SFLOAT', bytes: 16, array: Float32Array, per: 4, gl: ['RGBA32F', 'RGBA', 'FLOAT'] },
    122: { name: 'B10G11R11_UFLOAT_PACK32', bytes: 4, array: Uint32Array, per: 1,
           gl: ['R11F_G11F_B10F', 'RGB', 'UNSIGNED_INT_10F_11F_11F_REV'] },
    123: { name: 'E5B9G9R9_UFLOAT_PACK32', bytes: 4, array: Uint32Array, per: 1,
           gl: ['RGB9_E5', 'RGB', 'UNSIGNED_INT_5_9_9_9_REV'] },
    143: { name: 'BC6H_UFLOAT_BLOCK', block: 4, bytes: 16, array: Uint8Array,
           extension: 'EXT_texture_compression_bptc', internal: 'COMPRESSED_RGB_BPTC_UNSIGNED_FLOAT_EXT', option: 'bc6h' },
    1000066000: { name: 'ASTC_4x4_SFLOAT_BLOCK', block: 4, bytes: 16, array: Uint8Array,
                  extension: 'WEBGL_compressed_texture_astc', internal: 'COMPRESSED_RGBA_ASTC_4x4_KHR', profile: 'hdr', option: 'astc4x4' },
    1000066004: { name: 'ASTC_6x6_SFLOAT_BLOCK', block: 6, bytes: 16, array: Uint8Array,
                  extension: 'WEBGL_compressed_texture_astc', internal: 'COMPRESSED_RGBA_ASTC_6x6_KHR', profile: 'hdr', option: 'astc6x6' },
};

/// Bytes of one s x s face of `format`: s^2 texels, or ceil(s / b)^2 blocks of 16 bytes (a level
/// smaller than a block is one block).
export function faceBytes(format, s) {
    if (!format.block) return s * s * format.bytes;
    const b = Math.ceil(s / format.block);
    return b * b * format.bytes;
}

/// Parses a KTX2 cubemap. Result: { vkFormat, format, size, levels: [{ size, faces: [6 typed arrays] }] },
/// faces in the order +X, -X, +Y, -Y, +Z, -Z, rows (block rows) from t = 0 (the library's and GL's order).
export function parseKtx2Cubemap(buffer, name = 'KTX2') {
    const bad = (what) => new Error(`${name}: ${what}`);
    if (buffer.byteLength < 80) throw bad('shorter than the KTX2 header');
    const u8 = new Uint8Array(buffer);
    const dv = new DataView(buffer);
    for (let i = 0; i < IDENTIFIER.length; ++i) if (u8[i] !== IDENTIFIER[i]) throw bad('not a KTX 2.0 file');
    const vkFormat = dv.getUint32(12, true);
    const width = dv.getUint32(20, true), height = dv.getUint32(24, true), depth = dv.getUint32(28, true);
    const layerCount = dv.getUint32(32, true), faceCount = dv.getUint32(36, true);
    const levelCount = Math.max(1, dv.getUint32(40, true));
    const supercompression = dv.getUint32(44, true);
    const format = KTX2_FORMATS[vkFormat];
    if (!format) throw bad(`vkFormat ${vkFormat} is not one of ibl-bake's (${Object.keys(KTX2_FORMATS).join(', ')})`);
    if (faceCount !== 6 || width !== height || depth !== 0 || layerCount > 1) throw bad('not a cubemap of square faces');
    if (supercompression === 2)
        throw bad('Zstandard-supercompressed (supercompressionScheme 2, ibl-bake --ktx2-zstd N): the viewer has no ' +
                  'Zstandard decoder (it is a static page without a build step); bake with --ktx2-zstd 0');
    if (supercompression !== 0) throw bad(`supercompressionScheme ${supercompression} is not supported`);
    if (80 + 24 * levelCount > buffer.byteLength) throw bad('level index out of bounds');
    const levels = [];
    for (let l = 0; l < levelCount; ++l) {
        const off = 80 + 24 * l;
        const byteOffset = Number(dv.getBigUint64(off, true));
        const byteLength = Number(dv.getBigUint64(off + 8, true));
        const s = Math.max(1, width >> l);
        const fb = faceBytes(format, s);
        if (byteLength < 6 * fb || byteOffset + 6 * fb > buffer.byteLength) throw bad(`level ${l} out of bounds`);
        if (byteOffset % format.array.BYTES_PER_ELEMENT !== 0) throw bad(`level ${l} misaligned`);
        const faces = [];
        for (let f = 0; f < 6; ++f)
            faces.push(new format.array(buffer, byteOffset + f * fb, fb / format.array.BYTES_PER_ELEMENT));
        levels.push({ size: s, faces });
    }
    return { vkFormat, format, size: width, levels };
}

/// IEEE binary16 bits -> number.
export function halfToFloat(h) {
    const s = h & 0x8000 ? -1 : 1, e = (h >> 10) & 0x1f, m = h & 0x3ff;
    if (e === 0) return s * m * 2 ** -24;
    if (e === 31) return m ? NaN : s * Infinity;
    return s * (1 + m / 1024) * 2 ** (e - 15);
}

/// Solid-angle weighted mean luminance (BT.709) of level `l` of an RGBA16F / RGBA32F cube (the
/// viewer's exposure when report.json is absent). Packed formats: null.
export function meanLuminance(cube, l = 0) {
    if (cube.format.per !== 4) return null;
    const lv = cube.levels[l], n = lv.size;
    const half = cube.vkFormat === 97;
    let sum = 0, wsum = 0;
    for (let f = 0; f < 6; ++f)
        for (let y = 0; y < n; ++y)
            for (let x = 0; x < n; ++x) {
                const u = (2 * x + 1) / n - 1, v = (2 * y + 1) / n - 1;
                const w = Math.pow(1 + u * u + v * v, -1.5); // texel solid angle ~ (1 + u^2 + v^2)^-3/2
                const i = 4 * (y * n + x), a = lv.faces[f];
                const rgb = half ? [halfToFloat(a[i]), halfToFloat(a[i + 1]), halfToFloat(a[i + 2])] : [a[i], a[i + 1], a[i + 2]];
                sum += w * (0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]);
                wsum += w;
            }
    return sum / wsum;
}
