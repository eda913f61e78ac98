// GlFunctions: the OpenGL 3.3 core functions levelset_render calls, loaded from a context's
// proc-address function (eglGetProcAddress or OSMesaGetProcAddress). Every gl* call goes
// through this table: libOSMesa and libOpenGL both export gl* symbols, so calling them directly
// would bind to whichever the linker met first (../shared/notes/stack.md).
// Only the functions levelset_render uses are listed (LEVELSET_GL_FUNCTIONS); a window context
// (GLFW in the desktop client) loads the same table from glfwGetProcAddress.
// Errors: Error{UnsupportedFormat, "OpenGL", "the context has no glX"} naming the first missing
// function. Cost: ~70 look-ups once per context. Threading: the table is plain data; use it on
// the thread where its context is current.
#pragma once

#include <GL/glcorearb.h>

namespace levelset::render {

using ProcAddress = void* (*)(const char* name);

struct GlFunctions {
#define LEVELSET_GL_FUNCTIONS(X)                                                                   \
  X(PFNGLGETSTRINGPROC, GetString) X(PFNGLGETERRORPROC, GetError) X(PFNGLVIEWPORTPROC, Viewport)     \
  X(PFNGLCLEARCOLORPROC, ClearColor) X(PFNGLCLEARPROC, Clear) X(PFNGLENABLEPROC, Enable)             \
  X(PFNGLDISABLEPROC, Disable) X(PFNGLDEPTHFUNCPROC, DepthFunc) X(PFNGLPOLYGONMODEPROC, PolygonMode) \
  X(PFNGLPOLYGONOFFSETPROC, PolygonOffset) X(PFNGLFINISHPROC, Finish)                                \
  X(PFNGLPIXELSTOREIPROC, PixelStorei) X(PFNGLREADPIXELSPROC, ReadPixels)                            \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers) X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)          \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                                                  \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus)                                          \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers) X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer)      \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers)                                                \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage)                                                \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer)                                        \
  X(PFNGLCREATESHADERPROC, CreateShader) X(PFNGLSHADERSOURCEPROC, ShaderSource)                      \
  X(PFNGLCOMPILESHADERPROC, CompileShader) X(PFNGLGETSHADERIVPROC, GetShaderiv)                      \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog) X(PFNGLDELETESHADERPROC, DeleteShader)              \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram) X(PFNGLATTACHSHADERPROC, AttachShader)                    \
  X(PFNGLLINKPROGRAMPROC, LinkProgram) X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                        \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog) X(PFNGLUSEPROGRAMPROC, UseProgram)                \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram) X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)        \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv) X(PFNGLUNIFORM3FPROC, Uniform3f)                    \
  X(PFNGLUNIFORM1IPROC, Uniform1i) X(PFNGLUNIFORM1FPROC, Uniform1f)                                  \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays) X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)          \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays) X(PFNGLGENBUFFERSPROC, GenBuffers)              \
  X(PFNGLBINDBUFFERPROC, BindBuffer) X(PFNGLBUFFERDATAPROC, BufferData)                              \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers) X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer)      \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray) X(PFNGLDRAWARRAYSPROC, DrawArrays)    \
  X(PFNGLDRAWELEMENTSPROC, DrawElements) X(PFNGLUNIFORM4FPROC, Uniform4f) X(PFNGLBLENDFUNCPROC, BlendFunc)   \
  X(PFNGLDEPTHMASKPROC, DepthMask) X(PFNGLGENTEXTURESPROC, GenTextures)                              \
  X(PFNGLBINDTEXTUREPROC, BindTexture) X(PFNGLDELETETEXTURESPROC, DeleteTextures)                    \
  X(PFNGLTEXPARAMETERIPROC, TexParameteri) X(PFNGLTEXIMAGE3DPROC, TexImage3D)                        \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture) X(PFNGLVERTEXATTRIB1FPROC, VertexAttrib1f)               \
  X(PFNGLDISABLEVERTEXATTRIBARRAYPROC, DisableVertexAttribArray)
#define LEVELSET_GL_MEMBER(type, name) type name = nullptr;
  LEVELSET_GL_FUNCTIONS(LEVELSET_GL_MEMBER)
#undef LEVELSET_GL_MEMBER
};

GlFunctions load_gl_functions(ProcAddress proc_address);

}  // namespace levelset::render
