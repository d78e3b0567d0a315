// traversal kernel of the thesis grid — Müller 2015, ch. 3.2.4 (Fig. 15) and 4.2.2,
// Listing 21, Algorithms 2 and 3.
// One invocation per ray: the ray is walked through the grid (the same walk as the build
// kernel's edges) and the ids of the non-empty voxels it passes are stored in traversal order
// in its section of rayslist (ray_array_length entries), the count in raycontains.
// traversalMode 0: the eye / reflected rays of the ray-state textures; 1: the shadow feelers
// towards light lightSource (the thesis traverses both, ch. 3.2.4), or ours, towards one sample
// of an area light (common/light_target.glsl).
// Ours: the ray is first clipped to the grid box (the thesis' rays start inside [-1, 1)³).
// A full list drops the remaining voxels: ray_list_overflows counts them.
layout(local_size_x = 8, local_size_y = 8) in;

#define SCENE_QUALIFIER readonly
#define COUNTER_SLOTS_PER_KERNEL 2
#include "../common/scene.glsl"
#include "../common/images.glsl"
#include "../common/counters.glsl"
#include "../common/grid.glsl"
#include "../common/light_target.glsl"

// The thesis' block names (Listing 19), though VerticesInVoxel holds triangle ids (N³ lists of
// voxel_array_length) and ContainedVertices the fill level of each voxel's list.
layout(std430, binding = SSBO_VOXELCONTAINS) readonly buffer ContainedVertices { int voxelcontains[]; };
layout(std430, binding = SSBO_RAYSLIST) writeonly buffer RaysList { int rayslist[]; };
layout(std430, binding = SSBO_RAYCONTAINS) writeonly buffer RayContains { int raycontains[]; };

uniform int traversalMode;

int start = 0;          // first position of this ray's list
int voxelListCounter = 0;
uint overflows = 0u;
uint truncated = 0u;

// Listing 21: store a voxel id in the ray's list (empty voxels are skipped by the caller)
// Two deviations: the listing's overflow check `voxelListCounter <= ray_array_length` lets
// one entry past the list be written (into the next ray's list); ours is `<`. And the listing
// increments voxelListCounter even when the list is full, so raycontains would count voxels
// that were never stored and Listing 22 would read past the list; ours counts stored voxels
// only and the dropped ones in ray_list_overflows.
void storeVoxelID(int voxID)
{
    if (voxID >= 0) {
        // catch an overflow of the list
        if (voxelListCounter < ray_array_length) {
            int i = start + voxelListCounter;
            rayslist[i] = voxID;
            voxelListCounter++;
        } else {
            overflows++;
        }
    }
}

void storeVoxel(ivec3 voxel)
{
    int id = getVoxelID(voxel);
    // empty voxels are skipped
    if (id >= 0 && voxelcontains[id] > 0) storeVoxelID(id);
}

#include "voxelwalk.glsl"

void walkRay(ivec2 storePos)
{
    vec4 originState = imageLoad(rayOriginTexture, storePos);
    if (originState.w <= 0.0) return;
    vec3 ro = originState.xyz;
    vec3 rd;
    float tEnd;
    if (traversalMode == 0) {
        rd = imageLoad(rayDirTexture, storePos).xyz;
        tEnd = 1.0 / 0.0;
    } else {
        vec3 toLight = feelerTarget() - ro;
        tEnd = length(toLight);
        rd = toLight / tEnd;
        // the light behind the surface: intersect2 sets the shadow without a test
        if (dot(imageLoad(normalTexture, storePos).xyz, rd) <= 0.0) return;
    }
    vec3 rog = toGridSpace(ro);
    vec3 rdg = rd * gridScale;
    vec2 span = clipToGrid(rog, rdg);
    float t0 = max(span.x, 0.0), t1 = min(span.y, tEnd);
    if (t0 > t1) return;
    vec3 p0 = rog + t0 * rdg, p1 = rog + t1 * rdg;
    traverseConnection(p0, p1, clampVoxel(getVoxel(p0)), clampVoxel(getVoxel(p1)));
}

void main()
{
    countersBegin();
    ivec2 storePos = pixelPosition();
    if (insideImage(storePos)) {
        int threadID = storePos.y * imageSize(rayOriginTexture).x + storePos.x;
        start = threadID * ray_array_length;
        walkRay(storePos);
        // the fill level of the ray's list. The thesis re-initialises rayslist and raycontains
        // before every traversal (ch. 3.2.4); ours does not clear rayslist: raycontains is
        // written for every pixel (0 for an inactive ray) and the intersection kernels read
        // only the entries below it, so stale entries are never read
        raycontains[threadID] = voxelListCounter;
    }
    countAdd(0, overflows);
    countAdd(1, truncated);
    countersEnd(0, COUNTER_RAY_LIST_OVERFLOWS);
    countersEnd(1, COUNTER_TRUNCATED_RAYS);
}
