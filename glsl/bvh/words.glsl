// The SAH BVH's word buffer — ours, after Wagner 2018's three textures of Fig. 4.3 (ch. 4.2)
// in one buffer (Bvh::gpu_words in src/reference/bvh/mod.rs; its layout: bvh/traverse.glsl),
// read as RGBA32UI texels of 4 words, for bvh/traverse.glsl and bvh/hit_record.glsl.
layout(rgba32ui, binding = IMAGE_BVH) readonly uniform uimageBuffer bvh;

// The texel at word address `at` (a multiple of 4).
uvec4 bvhTexel(int at) { return imageLoad(bvh, at >> 2); }
