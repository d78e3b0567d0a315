// First in every kernel that stores the SAH BVH's records (bvh/records.glsl; ours): 64-bit
// integers where the profile takes them (RECORD_STORE_64, Profile::record_store_64), for the
// records' stores of two 64-bit words. An #extension comes before a shader's code, so the
// kernels include this file before any other.
#if RECORD_STORE_64
#extension GL_ARB_gpu_shader_int64 : require
#endif
