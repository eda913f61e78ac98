#include "render/gl_functions.hpp"

#include <string>

#include "core/error.hpp"

namespace levelset::render {

GlFunctions load_gl_functions(ProcAddress proc_address) {
  GlFunctions gl;
#define LEVELSET_GL_LOAD(type, name)                                                                   \
  gl.name = reinterpret_cast<type>(proc_address("gl" #name));                                         \
  if (gl.name == nullptr)                                                                              \
    throw Error(ErrorCode::UnsupportedFormat, "OpenGL", std::string("the context has no gl" #name));
  LEVELSET_GL_FUNCTIONS(LEVELSET_GL_LOAD)
#undef LEVELSET_GL_LOAD
  return gl;
}

}  // namespace levelset::render
