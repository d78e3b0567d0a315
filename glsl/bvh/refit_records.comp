// The refit's last pass — ours (bvh/refit.glsl: after Wald et al. 2007's refit): one invocation
// per node. Each finds the grid of the records' planes over the root's new box (Grid::over in
// src/accel/bvh/planes.rs), quantises its node's box onto it conservatively (Grid::planes: the
// low planes rounded down, the high ones up, so that the record still holds its subtree) and
// writes its record in every octant's copy (NodeRecord, BvhTree::octant_records in
// src/accel/bvh/layout.rs) with the record's `reference` made from one word of the topology per
// node (a miss link is the record's texel plus its subtree's size in every octant's depth-first
// copy; leaf triangles are the build's), so no texel is read; node 0's invocation writes the
// Header's grid.
// The planes are the host's, bit for bit: a first guess in floats (a step count off by a few at
// most), then the host's test in doubles, where a plane origin + q·step is exact (q has 16 bits,
// step 24), moves it to the tightest plane that holds the box.
#include "refit.glsl"

const double GRID_MAX = double(BVH_GRID_STEPS);

// Ours: with refitViews set (the host's, where it could make them: REFIT_VIEWS, the units, and
// the texel counts) a node's box and its 8 record texels and reference word are read through
// image buffers over the same storage (RGBA32F boxes, RGBA32UI topology: the 8 texel indices
// are two texels) — llvmpipe loads a storage-buffer vector lane by lane and component by
// component, an image texel for all lanes at once (docs/design/frame.md).
#if REFIT_VIEWS
layout(rgba32ui, binding = IMAGE_REFIT_TOPOLOGY) readonly uniform uimageBuffer topologyTexels;
layout(rgba32f, binding = IMAGE_REFIT_BOXES) readonly uniform imageBuffer boxTexels;
#endif
uniform int refitViews;

// Node k's box (lo, hi), the texels of its 8 octant records and its reference word.
void nodeInputs(int k, out vec3 lo, out vec3 hi, out uvec4 texels0, out uvec4 texels1,
                out uint referenceWord)
{
#if REFIT_VIEWS
    if (refitViews != 0) {
        lo = imageLoad(boxTexels, 2 * k).xyz;
        hi = imageLoad(boxTexels, 2 * k + 1).xyz;
        // recordTexel's words 4N + 8k + o, referenceWord's 12N + k (refit.glsl)
        texels0 = imageLoad(topologyTexels, nodeCount + 2 * k);
        texels1 = imageLoad(topologyTexels, nodeCount + 2 * k + 1);
        referenceWord = imageLoad(topologyTexels, 3 * nodeCount + (k >> 2))[k & 3];
        return;
    }
#endif
    lo = boxes[2 * k].xyz;
    hi = boxes[2 * k + 1].xyz;
    texels0 = uvec4(recordTexel(k, 0), recordTexel(k, 1), recordTexel(k, 2), recordTexel(k, 3));
    texels1 = uvec4(recordTexel(k, 4), recordTexel(k, 5), recordTexel(k, 6), recordTexel(k, 7));
    referenceWord = topology[12 * nodeCount + k];
}

vec3 gridOrigin = vec3(0.0), gridStep = vec3(1.0);

// Grid::over: the root's low corner and per axis the smallest float step whose BVH_GRID_STEPS
// steps reach the high side, no smaller than 2^-40 of the axis's coordinates; the unit grid at 0
// for a root that is no box.
void gridOver(vec3 lo, vec3 hi)
{
    if (any(isnan(lo)) || any(isinf(lo)) || any(isnan(hi)) || any(isinf(hi))
            || any(greaterThan(lo, hi))) return;
    gridOrigin = lo;
    for (int a = 0; a < 3; a++) {
        double extent = double(hi[a]) - double(lo[a]);
        float spacing = max(abs(lo[a]), abs(hi[a])) * uintBitsToFloat(uint(127 - 40) << 23);
        float s = max(float(extent / GRID_MAX), max(spacing, uintBitsToFloat(0x00800000u)));
        while (double(s) * GRID_MAX < extent) s = uintBitsToFloat(floatBitsToUint(s) + 1u);
        gridStep[a] = s;
    }
}

double plane(int a, double q) { return double(gridOrigin[a]) + q * double(gridStep[a]); }

// Grid::planes for one axis: the tightest planes (low, high) that hold [lo, hi]. The guesses
// come from floats; the loops, in doubles, make them exact whatever the guesses were.
uvec2 axisPlanes(int a, float lo, float hi)
{
    float o = gridOrigin[a], s = gridStep[a], top = float(BVH_GRID_STEPS);
    double l = double(clamp(floor((lo - o) / s), 0.0, top));
    while (l > 0.0LF && plane(a, l) > double(lo)) l -= 1.0LF;
    while (l < GRID_MAX && plane(a, l + 1.0LF) <= double(lo)) l += 1.0LF;
    double h = double(clamp(ceil((hi - o) / s), 0.0, top));
    while (h < GRID_MAX && plane(a, h) < double(hi)) h += 1.0LF;
    while (h > 0.0LF && plane(a, h - 1.0LF) >= double(hi)) h -= 1.0LF;
    return uvec2(uint(l), uint(h));
}

void main()
{
    int k = passNode(false);
    if (k < 0) return;
    gridOver(boxes[0].xyz, boxes[1].xyz);
    if (k == 0) {
        storeTexel(0, uvec4(uint(nodeCount), floatBitsToUint(gridOrigin)));
        storeTexel(1, uvec4(floatBitsToUint(gridStep), 0u));
    }
    vec3 lo, hi;
    uvec4 texels0, texels1;
    uint referenceWord;
    nodeInputs(k, lo, hi, texels0, texels1, referenceWord);
    uvec3 low, high;
    for (int a = 0; a < 3; a++) {
        uvec2 q = axisPlanes(a, lo[a], hi[a]);
        low[a] = q.x;
        high[a] = q.y;
    }
    for (int o = 0; o < 8; o++) {
        // octant_planes: the near plane is the low one unless the octant's rays point down
        bvec3 down = bvec3((o & 1) != 0, (o & 2) != 0, (o & 4) != 0);
        uvec3 near = mix(low, high, down), far = mix(high, low, down);
        uint texel = o < 4 ? texels0[o] : texels1[o - 4];
        storeTexel(int(texel), uvec4(near.x | near.y << 16u, near.z | far.x << 16u,
                                     far.y | far.z << 16u, referenceOf(referenceWord, texel)));
    }
}
