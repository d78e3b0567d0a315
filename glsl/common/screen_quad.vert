// Screen-filling quad, vertex stage — Müller 2015, ch. 3.1.3 (and ch. 3.3: the scene object
// keeps the quad's vertex positions). To show the output texture on the screen, a vertex-shader
// program that processes only the quad's positions hands texture coordinates to the fragment
// shader (glsl/common/screen_quad.frag).
// The quad is two triangles (a strip of 4 vertices) covering clip space [-1, 1]²; the viewer
// sets the viewport to the part of the window the image fills.

layout(location = 0) in vec2 position;

out vec2 texCoord;

void main()
{
    // clip space [-1, 1] -> texture space [0, 1]; the output texture is in GL row order
    // (row 0 = bottom), like the window, so no flip is needed
    texCoord = position * 0.5 + 0.5;
    gl_Position = vec4(position, 0.0, 1.0);
}
