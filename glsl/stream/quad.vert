// The viewport-sized quadrilateral — the streaming tracer, ch. 3, Fig. 1: "The input stream and
// execution of all the fragment programs is initialized in the same way, by rasterizing a viewport
// sized quadrilateral." Four vertices of a triangle strip from gl_VertexID (no vertex buffer), at
// depth 0 (window depth 0.5, which the early-Z pass's depth values 0 and 1 bracket). Every
// fragment is one ray; its pixel is gl_FragCoord.xy.
void main()
{
    vec2 p = vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
