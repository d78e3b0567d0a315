// The SAH BVH's word buffer — ours, after Wagner 2018's three textures of Fig. 4.3 (ch. 4.2)
// in one buffer (BvhTree::gpu_words in src/accel/bvh/layout.rs; its layout: bvh/traverse.glsl),
// read as RGBA32UI texels of 4 words, for bvh/traverse.glsl and bvh/hit_record.glsl.
// (bvh/entry.comp defines BVH_WORDS_WRITABLE: it writes the blocks' entries, bvh/entries.glsl)
// (included by both of those in bvh/fused_pass.comp: once)
#ifndef BVH_WORDS_GLSL
#define BVH_WORDS_GLSL
#ifdef BVH_WORDS_WRITABLE
layout(rgba32ui, binding = IMAGE_BVH) uniform uimageBuffer bvh;
#else
layout(rgba32ui, binding = IMAGE_BVH) readonly uniform uimageBuffer bvh;
#endif

// The texel of index `texel` (a node record). Its index masked to BVH_TEXEL_INDEX_MASK (the
// host's: the buffer has fewer texels, so no valid index changes): llvmpipe's LLVM then knows
// the index is not negative and zero-extends each lane's texel offset for free, where it
// sign-extended them (8 `movslq` per texel load; docs/design/bvh.md, step 19).
uvec4 bvhRecord(int texel) { return imageLoad(bvh, int(uint(texel) & BVH_TEXEL_INDEX_MASK)); }
// The texel at word address `at` (a multiple of 4: the header, a leaf triangle).
uvec4 bvhTexel(int at) { return bvhRecord(int(uint(at) >> 2u)); }

// A node record's box (NodeRecord in src/accel/bvh/layout.rs: near, far): the planes where rays
// of its octant enter the slabs (near) and leave them (far), 16-bit step counts on the grid
// (bvh/traverse.glsl).
void recordPlanes(uvec4 record, out vec3 near, out vec3 far)
{
    near = vec3(ivec3(record.x & 0xffffu, record.x >> 16u, record.y & 0xffffu));
    far = vec3(ivec3(record.y >> 16u, record.z & 0xffffu, record.z >> 16u));
}

// Two levels (ours; BVH_INSTANCES, src/accel/bvh/instances.rs): texel 0 holds the instance
// count, instance k's InstanceRecord (BVH_INSTANCE_TEXELS texels) starts at texel
// 1 + k·BVH_INSTANCE_TEXELS — its world box (lo, and its tree's texel in lo's w; hi), then the
// rows of the inverse of its model matrix. The ray ro + t·rd in instance k's object space, with
// the same t (an affine map, the direction not normalised): one function for the walk
// (bvh/traverse.glsl) and the hit record (bvh/hit_record.glsl), so that both find the same t.
void instanceRay(int k, vec3 ro, vec3 rd, out vec3 o, out vec3 d)
{
    int at = 1 + k * BVH_INSTANCE_TEXELS + 2;
    vec4 r0 = uintBitsToFloat(bvhRecord(at));
    vec4 r1 = uintBitsToFloat(bvhRecord(at + 1));
    vec4 r2 = uintBitsToFloat(bvhRecord(at + 2));
    o = vec3(dot(r0.xyz, ro) + r0.w, dot(r1.xyz, ro) + r1.w, dot(r2.xyz, ro) + r2.w);
    d = vec3(dot(r0.xyz, rd), dot(r1.xyz, rd), dot(r2.xyz, rd));
}
#endif
