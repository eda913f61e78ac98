// The GLSL 3.30 programs of levelset_render and a compile + link helper.
// - surface: triangles / points / lines of the mesh, lit (smooth normals or flat from screen
//   derivatives) or unlit, optionally coloured by a per-vertex scalar (curvature).
// - markers: band voxels as points or vectors, coloured by value through the diverging map, or
//   one colour; voxels outside [range_min, range_max] are discarded.
// - slice: a quad through the band's texture, the diverging map with the zero contour in black.
// - volume: ray casting through the band's texture (a full-screen triangle): a transfer
//   function on the value, Phong shading from the gradient, front-to-back compositing and
//   empty-space skipping (the values are distances).
// Diverging map: value / scale in -1..1, inside (negative) red through white to blue outside.
// Errors: Error{IoError, "shader <name>"} with the driver's log. Threading: context thread.
#pragma once

#include "render/gl_functions.hpp"

namespace levelset::render {

enum class Program { Surface, Markers, Slice, Volume };

// Compiles and links one program (the caller deletes it with gl.DeleteProgram).
unsigned build_program(const GlFunctions& gl, Program program);

}  // namespace levelset::render
