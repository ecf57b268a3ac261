#include <GL/osmesa.h>
// glext.h needs the GL types that osmesa.h (through gl.h) declares first.
#include <GL/glext.h>
#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "render/renderer.h"
#include "render/view_renderer.h"

namespace ratslam::render {
namespace {

// The OpenGL entry points we use, resolved through OSMesaGetProcAddress.
struct GlFunctions {
#define RATSLAM_GL_FUNCTIONS(X)                                                             \
  X(decltype(&::glGetError), GetError, "glGetError")                                        \
  X(decltype(&::glGetIntegerv), GetIntegerv, "glGetIntegerv")                               \
  X(decltype(&::glViewport), Viewport, "glViewport")                                        \
  X(decltype(&::glClearColor), ClearColor, "glClearColor")                                  \
  X(decltype(&::glClear), Clear, "glClear")                                                 \
  X(decltype(&::glEnable), Enable, "glEnable")                                              \
  X(PFNGLBLENDFUNCSEPARATEPROC, BlendFuncSeparate, "glBlendFuncSeparate")                   \
  X(decltype(&::glReadPixels), ReadPixels, "glReadPixels")                                  \
  X(decltype(&::glPixelStorei), PixelStorei, "glPixelStorei")                               \
  X(decltype(&::glFinish), Finish, "glFinish")                                              \
  X(PFNGLGENBUFFERSPROC, GenBuffers, "glGenBuffers")                                        \
  X(PFNGLDELETEBUFFERSPROC, DeleteBuffers, "glDeleteBuffers")                               \
  X(PFNGLBINDBUFFERPROC, BindBuffer, "glBindBuffer")                                        \
  X(PFNGLBUFFERDATAPROC, BufferData, "glBufferData")                                        \
  X(PFNGLGENVERTEXARRAYSPROC, GenVertexArrays, "glGenVertexArrays")                         \
  X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays, "glDeleteVertexArrays")                \
  X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray, "glBindVertexArray")                         \
  X(PFNGLVERTEXATTRIBPOINTERPROC, VertexAttribPointer, "glVertexAttribPointer")             \
  X(PFNGLENABLEVERTEXATTRIBARRAYPROC, EnableVertexAttribArray, "glEnableVertexAttribArray") \
  X(PFNGLCREATESHADERPROC, CreateShader, "glCreateShader")                                  \
  X(PFNGLDELETESHADERPROC, DeleteShader, "glDeleteShader")                                  \
  X(PFNGLSHADERSOURCEPROC, ShaderSource, "glShaderSource")                                  \
  X(PFNGLCOMPILESHADERPROC, CompileShader, "glCompileShader")                               \
  X(PFNGLGETSHADERIVPROC, GetShaderiv, "glGetShaderiv")                                     \
  X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog, "glGetShaderInfoLog")                      \
  X(PFNGLCREATEPROGRAMPROC, CreateProgram, "glCreateProgram")                               \
  X(PFNGLDELETEPROGRAMPROC, DeleteProgram, "glDeleteProgram")                               \
  X(PFNGLATTACHSHADERPROC, AttachShader, "glAttachShader")                                  \
  X(PFNGLLINKPROGRAMPROC, LinkProgram, "glLinkProgram")                                     \
  X(PFNGLGETPROGRAMIVPROC, GetProgramiv, "glGetProgramiv")                                  \
  X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog, "glGetProgramInfoLog")                   \
  X(PFNGLUSEPROGRAMPROC, UseProgram, "glUseProgram")                                        \
  X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation, "glGetUniformLocation")                \
  X(PFNGLUNIFORM2FPROC, Uniform2f, "glUniform2f")                                           \
  X(PFNGLUNIFORM1IPROC, Uniform1i, "glUniform1i")                                           \
  X(PFNGLUNIFORM1FPROC, Uniform1f, "glUniform1f")                                           \
  X(PFNGLUNIFORM3FPROC, Uniform3f, "glUniform3f")                                           \
  X(PFNGLUNIFORMMATRIX4FVPROC, UniformMatrix4fv, "glUniformMatrix4fv")                      \
  X(decltype(&::glDisable), Disable, "glDisable")                                           \
  X(decltype(&::glDrawArrays), DrawArrays, "glDrawArrays")                                  \
  X(decltype(&::glGenTextures), GenTextures, "glGenTextures")                               \
  X(decltype(&::glDeleteTextures), DeleteTextures, "glDeleteTextures")                      \
  X(decltype(&::glBindTexture), BindTexture, "glBindTexture")                               \
  X(decltype(&::glTexImage2D), TexImage2D, "glTexImage2D")                                  \
  X(decltype(&::glTexParameteri), TexParameteri, "glTexParameteri")                         \
  X(PFNGLACTIVETEXTUREPROC, ActiveTexture, "glActiveTexture")                               \
  X(PFNGLGENFRAMEBUFFERSPROC, GenFramebuffers, "glGenFramebuffers")                         \
  X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers, "glDeleteFramebuffers")                \
  X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer, "glBindFramebuffer")                         \
  X(PFNGLCHECKFRAMEBUFFERSTATUSPROC, CheckFramebufferStatus, "glCheckFramebufferStatus")    \
  X(PFNGLGENRENDERBUFFERSPROC, GenRenderbuffers, "glGenRenderbuffers")                      \
  X(PFNGLDELETERENDERBUFFERSPROC, DeleteRenderbuffers, "glDeleteRenderbuffers")             \
  X(PFNGLBINDRENDERBUFFERPROC, BindRenderbuffer, "glBindRenderbuffer")                      \
  X(PFNGLRENDERBUFFERSTORAGEMULTISAMPLEPROC, RenderbufferStorageMultisample,                \
    "glRenderbufferStorageMultisample")                                                     \
  X(PFNGLRENDERBUFFERSTORAGEPROC, RenderbufferStorage, "glRenderbufferStorage")             \
  X(PFNGLFRAMEBUFFERRENDERBUFFERPROC, FramebufferRenderbuffer, "glFramebufferRenderbuffer") \
  X(PFNGLBLITFRAMEBUFFERPROC, BlitFramebuffer, "glBlitFramebuffer")
#define RATSLAM_DECLARE(type, name, symbol) type name = nullptr;
  RATSLAM_GL_FUNCTIONS(RATSLAM_DECLARE)
#undef RATSLAM_DECLARE
};

using CreateContextAttribsFn = OSMesaContext (*)(const int*, OSMesaContext);
using MakeCurrentFn = GLboolean (*)(OSMesaContext, void*, GLenum, GLsizei, GLsizei);
using DestroyContextFn = void (*)(OSMesaContext);
using GetProcAddressFn = OSMESAproc (*)(const char*);

const char kColorVertexShader[] = R"(#version 330 core
layout(location = 0) in vec2 position_px;
layout(location = 1) in vec4 color;
uniform vec2 viewport_px;
out vec4 vertex_color;
void main() {
  // Scene row 0 goes to OpenGL's first row in memory (its bottom), so glReadPixels returns the
  // image top row first and needs no flip.
  gl_Position = vec4(position_px.x / viewport_px.x * 2.0 - 1.0,
                     position_px.y / viewport_px.y * 2.0 - 1.0, 0.0, 1.0);
  vertex_color = color;
}
)";
const char kColorFragmentShader[] = R"(#version 330 core
in vec4 vertex_color;
out vec4 fragment_color;
void main() { fragment_color = vertex_color; }
)";
const char kTextureVertexShader[] = R"(#version 330 core
layout(location = 0) in vec2 position_px;
layout(location = 1) in vec2 texture_coordinate;
uniform vec2 viewport_px;
out vec2 uv;
void main() {
  gl_Position = vec4(position_px.x / viewport_px.x * 2.0 - 1.0,
                     position_px.y / viewport_px.y * 2.0 - 1.0, 0.0, 1.0);
  uv = texture_coordinate;
}
)";
const char kTextureFragmentShader[] = R"(#version 330 core
in vec2 uv;
uniform sampler2D image;
out vec4 fragment_color;
void main() { fragment_color = texture(image, uv); }
)";

// An OSMesa OpenGL 3.3 core context with its entry points, shared by both renderers.
class OsMesaContextHolder {
 public:
  virtual ~OsMesaContextHolder() {
    if (context_) destroy_context_(context_);
    // The library stays loaded: Mesa keeps process-wide state (llvmpipe threads, LLVM) that is
    // not meant to be unloaded, and a later renderer reuses it.
  }

  Status InitContext() {
    // RATSLAM_OSMESA_LIBRARY names a specific build; otherwise try the usual sonames, which
    // differ between Mesa releases.
    if (const char* override_path = std::getenv("RATSLAM_OSMESA_LIBRARY")) {
      library_ = dlopen(override_path, RTLD_NOW | RTLD_LOCAL);
      if (!library_) {
        return Status::Error(std::string("OSMesa is not available: cannot load ") + override_path +
                             " (RATSLAM_OSMESA_LIBRARY): " + dlerror());
      }
    } else {
      for (const char* name : {"libOSMesa.so.8", "libOSMesa.so.6", "libOSMesa.so"}) {
        library_ = dlopen(name, RTLD_NOW | RTLD_LOCAL);
        if (library_) break;
      }
    }
    if (!library_) {
      return Status::Error(
          "OSMesa is not available (cannot load libOSMesa.so.8; install the Debian package "
          "libosmesa6): images cannot be rendered");
    }
    auto create =
        reinterpret_cast<CreateContextAttribsFn>(dlsym(library_, "OSMesaCreateContextAttribs"));
    make_current_ = reinterpret_cast<MakeCurrentFn>(dlsym(library_, "OSMesaMakeCurrent"));
    destroy_context_ = reinterpret_cast<DestroyContextFn>(dlsym(library_, "OSMesaDestroyContext"));
    auto get_proc = reinterpret_cast<GetProcAddressFn>(dlsym(library_, "OSMesaGetProcAddress"));
    if (!create || !make_current_ || !destroy_context_ || !get_proc) {
      return Status::Error("OSMesa library lacks OSMesaCreateContextAttribs (Mesa too old?)");
    }
    const int attributes[] = {OSMESA_FORMAT,
                              OSMESA_RGBA,
                              OSMESA_DEPTH_BITS,
                              0,
                              OSMESA_PROFILE,
                              OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION,
                              3,
                              OSMESA_CONTEXT_MINOR_VERSION,
                              3,
                              0};
    context_ = create(attributes, nullptr);
    if (!context_) return Status::Error("OSMesa: cannot create an OpenGL 3.3 core context");
    dummy_.assign(4 * 4 * 4, 0);
    if (!make_current_(context_, dummy_.data(), GL_UNSIGNED_BYTE, 4, 4)) {
      return Status::Error("OSMesa: cannot make the context current");
    }
#define RATSLAM_LOAD(type, name, symbol)               \
  gl_.name = reinterpret_cast<type>(get_proc(symbol)); \
  if (!gl_.name) return Status::Error(std::string("OSMesa: missing ") + symbol);
    RATSLAM_GL_FUNCTIONS(RATSLAM_LOAD)
#undef RATSLAM_LOAD
    gl_.GetIntegerv(GL_MAX_SAMPLES, &max_samples_);
    gl_.GetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size_);
    return Status::Ok();
  }

  bool MakeCurrent() { return make_current_(context_, dummy_.data(), GL_UNSIGNED_BYTE, 4, 4); }

  StatusOr<GLuint> Shader(GLenum type, const char* source) {
    const GLuint shader = gl_.CreateShader(type);
    gl_.ShaderSource(shader, 1, &source, nullptr);
    gl_.CompileShader(shader);
    GLint ok = 0;
    gl_.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[1024] = {};
      gl_.GetShaderInfoLog(shader, sizeof log, nullptr, log);
      gl_.DeleteShader(shader);
      return Status::Error(std::string("OpenGL shader does not compile: ") + log);
    }
    return shader;
  }

  StatusOr<GLuint> Program(const char* vertex, const char* fragment) {
    StatusOr<GLuint> vs = Shader(GL_VERTEX_SHADER, vertex);
    if (!vs.ok()) return vs.status();
    StatusOr<GLuint> fs = Shader(GL_FRAGMENT_SHADER, fragment);
    if (!fs.ok()) return fs.status();
    const GLuint program = gl_.CreateProgram();
    gl_.AttachShader(program, vs.value());
    gl_.AttachShader(program, fs.value());
    gl_.LinkProgram(program);
    gl_.DeleteShader(vs.value());
    gl_.DeleteShader(fs.value());
    GLint ok = 0;
    gl_.GetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[1024] = {};
      gl_.GetProgramInfoLog(program, sizeof log, nullptr, log);
      gl_.DeleteProgram(program);
      return Status::Error(std::string("OpenGL program does not link: ") + log);
    }
    return program;
  }

 protected:
  void* library_ = nullptr;
  OSMesaContext context_ = nullptr;
  MakeCurrentFn make_current_ = nullptr;
  DestroyContextFn destroy_context_ = nullptr;
  std::vector<uint8_t> dummy_;
  GlFunctions gl_;
  GLint max_samples_ = 1, max_size_ = 0;
};

class OsMesaRenderer : public SceneRenderer, public OsMesaContextHolder {
 public:
  ~OsMesaRenderer() override {
    if (gl_.DeleteProgram && context_ && MakeCurrent()) {
      ReleaseFramebuffers();
      gl_.DeleteProgram(color_program_);
      gl_.DeleteProgram(texture_program_);
    }
  }

  Status Init() {
    RATSLAM_RETURN_IF_ERROR(InitContext());
    StatusOr<GLuint> color = Program(kColorVertexShader, kColorFragmentShader);
    if (!color.ok()) return color.status();
    color_program_ = color.value();
    StatusOr<GLuint> texture = Program(kTextureVertexShader, kTextureFragmentShader);
    if (!texture.ok()) return texture.status();
    texture_program_ = texture.value();
    return Status::Ok();
  }

  StatusOr<RgbaImage> Render(const Scene& scene) override {
    const int w = scene.width(), h = scene.height();
    if (w <= 0 || h <= 0 || w > max_size_ || h > max_size_) {
      return Status::Error("image size " + std::to_string(w) + "x" + std::to_string(h) +
                           " outside 1.." + std::to_string(max_size_));
    }
    if (!MakeCurrent()) return Status::Error("OSMesa: cannot make the context current");
    // A multisampled framebuffer for antialiasing, resolved into a plain one for reading; kept
    // for the next image of the same size (allocating them costs about 35 ms at 2048x2048).
    if (w != framebuffer_width_ || h != framebuffer_height_) {
      RATSLAM_RETURN_IF_ERROR(AllocateFramebuffers(w, h));
    }
    gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffers_[0]);
    gl_.Viewport(0, 0, w, h);
    const Rgba bg = scene.background();
    gl_.ClearColor(bg.r / 255.f, bg.g / 255.f, bg.b / 255.f, bg.a / 255.f);
    gl_.Clear(GL_COLOR_BUFFER_BIT);
    gl_.Enable(GL_BLEND);
    gl_.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    gl_.Enable(GL_MULTISAMPLE);
    for (const SceneImage& img : scene.images()) DrawImage(img, w, h);
    DrawTriangles(scene.triangles(), w, h);
    gl_.BindFramebuffer(GL_READ_FRAMEBUFFER, framebuffers_[0]);
    gl_.BindFramebuffer(GL_DRAW_FRAMEBUFFER, framebuffers_[1]);
    gl_.BlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffers_[1]);
    // The shaders put scene row 0 first in memory: the rows come out top first.
    RgbaImage image;
    image.width = w;
    image.height = h;
    image.pixels.resize(static_cast<size_t>(w) * h * 4);
    gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl_.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, image.pixels.data());
    gl_.Finish();
    const GLenum error = gl_.GetError();
    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    if (error != GL_NO_ERROR) {
      ReleaseFramebuffers();
      return Status::Error("OpenGL error " + std::to_string(error) + " while rendering");
    }
    DrawTexts(scene, &image);
    return image;
  }

 private:
  Status AllocateFramebuffers(int w, int h) {
    ReleaseFramebuffers();
    const int samples = std::min(8, static_cast<int>(max_samples_));
    gl_.GenFramebuffers(2, framebuffers_);
    gl_.GenRenderbuffers(2, renderbuffers_);
    gl_.BindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[0]);
    gl_.RenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, w, h);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffers_[0]);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                renderbuffers_[0]);
    const bool ms_complete = gl_.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    gl_.BindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[1]);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffers_[1]);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                renderbuffers_[1]);
    const bool complete = gl_.CheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    framebuffer_width_ = w;
    framebuffer_height_ = h;
    if (!complete || !ms_complete) {
      ReleaseFramebuffers();
      return Status::Error("OSMesa: framebuffer incomplete for " + std::to_string(w) + "x" +
                           std::to_string(h));
    }
    return Status::Ok();
  }

  void ReleaseFramebuffers() {
    if (framebuffer_width_ == 0) return;  // none allocated
    gl_.DeleteFramebuffers(2, framebuffers_);
    gl_.DeleteRenderbuffers(2, renderbuffers_);
    framebuffer_width_ = framebuffer_height_ = 0;
  }

  void DrawTriangles(const std::vector<Scene::Vertex>& vertices, int w, int h) {
    if (vertices.empty()) return;
    static_assert(sizeof(Scene::Vertex) == 12, "vertex layout: 2 floats, 4 bytes");
    GLuint vao, vbo;
    gl_.GenVertexArrays(1, &vao);
    gl_.BindVertexArray(vao);
    gl_.GenBuffers(1, &vbo);
    gl_.BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl_.BufferData(GL_ARRAY_BUFFER, vertices.size() * sizeof(Scene::Vertex), vertices.data(),
                   GL_STREAM_DRAW);
    gl_.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(Scene::Vertex), nullptr);
    gl_.EnableVertexAttribArray(0);
    gl_.VertexAttribPointer(1, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Scene::Vertex),
                            reinterpret_cast<const void*>(8));
    gl_.EnableVertexAttribArray(1);
    gl_.UseProgram(color_program_);
    gl_.Uniform2f(gl_.GetUniformLocation(color_program_, "viewport_px"), w, h);
    gl_.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(vertices.size()));
    gl_.DeleteBuffers(1, &vbo);
    gl_.DeleteVertexArrays(1, &vao);
  }

  void DrawImage(const SceneImage& img, int w, int h) {
    if (img.pixels_wide <= 0 || img.pixels_high <= 0 ||
        img.rgba.size() != static_cast<size_t>(img.pixels_wide) * img.pixels_high * 4) {
      return;
    }
    GLuint texture;
    gl_.GenTextures(1, &texture);
    gl_.ActiveTexture(GL_TEXTURE0);
    gl_.BindTexture(GL_TEXTURE_2D, texture);
    gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, img.pixels_wide, img.pixels_high, 0, GL_RGBA,
                   GL_UNSIGNED_BYTE, img.rgba.data());
    const GLint filter = img.smooth ? GL_LINEAR : GL_NEAREST;
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, filter);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, filter);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    // Texture row 0 is the image's top row, drawn at the rectangle's top (v = 0).
    const float l = img.left, t = img.top, r = img.left + img.width, b = img.top + img.height;
    const float quad[] = {l, t, 0, 0, r, t, 1, 0, r, b, 1, 1, l, t, 0, 0, r, b, 1, 1, l, b, 0, 1};
    GLuint vao, vbo;
    gl_.GenVertexArrays(1, &vao);
    gl_.BindVertexArray(vao);
    gl_.GenBuffers(1, &vbo);
    gl_.BindBuffer(GL_ARRAY_BUFFER, vbo);
    gl_.BufferData(GL_ARRAY_BUFFER, sizeof quad, quad, GL_STREAM_DRAW);
    gl_.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), nullptr);
    gl_.EnableVertexAttribArray(0);
    gl_.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float),
                            reinterpret_cast<const void*>(2 * sizeof(float)));
    gl_.EnableVertexAttribArray(1);
    gl_.UseProgram(texture_program_);
    gl_.Uniform2f(gl_.GetUniformLocation(texture_program_, "viewport_px"), w, h);
    gl_.Uniform1i(gl_.GetUniformLocation(texture_program_, "image"), 0);
    gl_.DrawArrays(GL_TRIANGLES, 0, 6);
    gl_.DeleteBuffers(1, &vbo);
    gl_.DeleteVertexArrays(1, &vao);
    gl_.DeleteTextures(1, &texture);
  }

  GLuint color_program_ = 0, texture_program_ = 0;
  GLuint framebuffers_[2] = {0, 0}, renderbuffers_[2] = {0, 0};
  int framebuffer_width_ = 0, framebuffer_height_ = 0;  // 0: no framebuffers allocated
};

const char kViewVertexShader[] = R"(#version 330 core
layout(location = 0) in vec3 position_m;
layout(location = 1) in vec2 repeats;
layout(location = 2) in float tile;
layout(location = 3) in float shade;
uniform mat4 view_projection;
uniform vec3 camera_m;
out vec2 uv;
flat out float tile_index;
out float face_shade;
out float distance_m;
void main() {
  gl_Position = view_projection * vec4(position_m, 1.0);
  uv = repeats;
  tile_index = tile;
  face_shade = shade;
  distance_m = length(position_m - camera_m);
}
)";
const char kViewFragmentShader[] = R"(#version 330 core
in vec2 uv;
flat in float tile_index;
in float face_shade;
in float distance_m;
uniform sampler2D atlas;
uniform float tiles_per_side;
uniform float tile_px;
uniform float ambient;
uniform float headlight_gain;
uniform float headlight_range_m;
out vec4 fragment_color;
void main() {
  // The texture repeats: wrap inside its tile, half a texel in from the edges (no bleeding).
  float column = mod(tile_index, tiles_per_side);
  float row = floor(tile_index / tiles_per_side);
  float inset = 0.5 / tile_px;
  vec2 inside = inset + fract(uv) * (1.0 - 2.0 * inset);
  vec2 atlas_uv = (vec2(column, row) + inside) / tiles_per_side;
  float texel = texture(atlas, atlas_uv).r;
  float d = distance_m / headlight_range_m;
  float light = ambient + headlight_gain / (1.0 + d * d);
  float value = clamp(texel * face_shade * light, 0.0, 1.0);
  fragment_color = vec4(value, value, value, 1.0);
}
)";

class OsMesaViewRenderer : public ViewRenderer, public OsMesaContextHolder {
 public:
  ~OsMesaViewRenderer() override {
    if (gl_.DeleteProgram && context_ && MakeCurrent()) {
      gl_.DeleteProgram(program_);
      if (vbo_) gl_.DeleteBuffers(1, &vbo_);
      if (vao_) gl_.DeleteVertexArrays(1, &vao_);
      if (texture_) gl_.DeleteTextures(1, &texture_);
    }
  }

  Status Init() {
    RATSLAM_RETURN_IF_ERROR(InitContext());
    StatusOr<GLuint> program = Program(kViewVertexShader, kViewFragmentShader);
    if (!program.ok()) return program.status();
    program_ = program.value();
    return Status::Ok();
  }

  StatusOr<GrayImage> Render(const ViewMesh& mesh, const ViewCamera& camera,
                             const ViewLighting& lighting) override {
    const int w = camera.width_px, h = camera.height_px;
    if (w <= 0 || h <= 0 || w > max_size_ || h > max_size_) {
      return Status::Error("view size " + std::to_string(w) + "x" + std::to_string(h) +
                           " outside 1.." + std::to_string(max_size_));
    }
    const int atlas_px = mesh.tile_px * mesh.tiles_per_side;
    if (mesh.tile_px <= 0 || mesh.tiles_per_side <= 0 ||
        mesh.atlas.size() != static_cast<size_t>(atlas_px) * atlas_px) {
      return Status::Error("view mesh: the texture atlas does not match its size");
    }
    if (!(camera.horizontal_fov_deg > 1.0 && camera.horizontal_fov_deg < 179.0) ||
        !(camera.near_m > 0.0 && camera.far_m > camera.near_m)) {
      return Status::Error("view camera: field of view or clip distances out of range");
    }
    if (!MakeCurrent()) return Status::Error("OSMesa: cannot make the context current");
    Upload(mesh);
    GLuint framebuffer, renderbuffers[2];
    gl_.GenFramebuffers(1, &framebuffer);
    gl_.GenRenderbuffers(2, renderbuffers);
    gl_.BindRenderbuffer(GL_RENDERBUFFER, renderbuffers[0]);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, w, h);
    gl_.BindRenderbuffer(GL_RENDERBUFFER, renderbuffers[1]);
    gl_.RenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
    gl_.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER,
                                renderbuffers[0]);
    gl_.FramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                                renderbuffers[1]);
    Status status;
    GrayImage image;
    if (gl_.CheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      status = Status::Error("OSMesa: view framebuffer incomplete");
    } else {
      gl_.Viewport(0, 0, w, h);
      gl_.ClearColor(0.f, 0.f, 0.f, 1.f);
      gl_.Clear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
      gl_.Enable(GL_DEPTH_TEST);
      gl_.Disable(GL_BLEND);
      gl_.UseProgram(program_);
      float matrix[16];
      ViewProjection(camera, matrix);
      gl_.UniformMatrix4fv(gl_.GetUniformLocation(program_, "view_projection"), 1, GL_FALSE,
                           matrix);
      SetCameraUniform(camera);
      gl_.Uniform1f(gl_.GetUniformLocation(program_, "tiles_per_side"),
                    static_cast<float>(mesh.tiles_per_side));
      gl_.Uniform1f(gl_.GetUniformLocation(program_, "tile_px"), static_cast<float>(mesh.tile_px));
      gl_.Uniform1f(gl_.GetUniformLocation(program_, "ambient"),
                    static_cast<float>(lighting.ambient));
      gl_.Uniform1f(gl_.GetUniformLocation(program_, "headlight_gain"),
                    static_cast<float>(lighting.headlight_gain));
      gl_.Uniform1f(gl_.GetUniformLocation(program_, "headlight_range_m"),
                    static_cast<float>(std::max(1e-3, lighting.headlight_range_m)));
      gl_.ActiveTexture(GL_TEXTURE0);
      gl_.BindTexture(GL_TEXTURE_2D, texture_);
      gl_.Uniform1i(gl_.GetUniformLocation(program_, "atlas"), 0);
      gl_.BindVertexArray(vao_);
      gl_.DrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(mesh.triangles.size()));
      std::vector<uint8_t> bottom_up(static_cast<size_t>(w) * h * 4);
      gl_.PixelStorei(GL_PACK_ALIGNMENT, 1);
      gl_.ReadPixels(0, 0, w, h, GL_RGBA, GL_UNSIGNED_BYTE, bottom_up.data());
      gl_.Disable(GL_DEPTH_TEST);
      if (const GLenum error = gl_.GetError(); error != GL_NO_ERROR) {
        status = Status::Error("OpenGL error " + std::to_string(error) + " while rendering a view");
      }
      image.width = w;
      image.height = h;
      image.pixels.resize(static_cast<size_t>(w) * h);
      for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
          image.pixels[static_cast<size_t>(y) * w + x] =
              bottom_up[(static_cast<size_t>(h - 1 - y) * w + x) * 4];
        }
      }
    }
    gl_.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl_.DeleteFramebuffers(1, &framebuffer);
    gl_.DeleteRenderbuffers(2, renderbuffers);
    if (!status.ok()) return status;
    return image;
  }

 private:
  void Upload(const ViewMesh& mesh) {
    if (!vao_) {
      gl_.GenVertexArrays(1, &vao_);
      gl_.GenBuffers(1, &vbo_);
      gl_.GenTextures(1, &texture_);
    } else if (mesh.id == uploaded_id_ && mesh.triangles.size() == uploaded_vertices_ &&
               mesh.atlas_id == uploaded_atlas_id_) {
      return;
    }
    if (!atlas_uploaded_ || mesh.atlas_id != uploaded_atlas_id_) {
      const int atlas_px = mesh.tile_px * mesh.tiles_per_side;
      gl_.ActiveTexture(GL_TEXTURE0);
      gl_.BindTexture(GL_TEXTURE_2D, texture_);
      gl_.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
      gl_.TexImage2D(GL_TEXTURE_2D, 0, GL_R8, atlas_px, atlas_px, 0, GL_RED, GL_UNSIGNED_BYTE,
                     mesh.atlas.data());
      gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      gl_.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      uploaded_atlas_id_ = mesh.atlas_id;
      atlas_uploaded_ = true;
    }
    gl_.BindVertexArray(vao_);
    gl_.BindBuffer(GL_ARRAY_BUFFER, vbo_);
    static_assert(sizeof(ViewVertex) == 7 * sizeof(float), "vertex layout: 7 floats");
    gl_.BufferData(GL_ARRAY_BUFFER, mesh.triangles.size() * sizeof(ViewVertex),
                   mesh.triangles.data(), GL_STATIC_DRAW);
    const GLsizei stride = sizeof(ViewVertex);
    gl_.VertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, nullptr);
    gl_.EnableVertexAttribArray(0);
    gl_.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(12));
    gl_.EnableVertexAttribArray(1);
    gl_.VertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(20));
    gl_.EnableVertexAttribArray(2);
    gl_.VertexAttribPointer(3, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<const void*>(24));
    gl_.EnableVertexAttribArray(3);
    uploaded_id_ = mesh.id;
    uploaded_vertices_ = mesh.triangles.size();
  }

  void SetCameraUniform(const ViewCamera& c) {
    gl_.Uniform3f(gl_.GetUniformLocation(program_, "camera_m"), static_cast<float>(c.x_m),
                  static_cast<float>(c.y_m), static_cast<float>(c.z_m));
  }

  // Column-major projection * view for OpenGL.
  static void ViewProjection(const ViewCamera& c, float out[16]) {
    const double cy = std::cos(c.yaw_rad), sy = std::sin(c.yaw_rad);
    const double cp = std::cos(c.pitch_rad), sp = std::sin(c.pitch_rad);
    // Camera axes: forward f, right r, up u (world coordinates).
    const double f[3] = {cy * cp, sy * cp, sp};
    const double r[3] = {sy, -cy, 0.0};
    const double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2],
                         r[0] * f[1] - r[1] * f[0]};
    const double e[3] = {c.x_m, c.y_m, c.z_m};
    auto dot = [](const double* a, const double* b) {
      return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    };
    // View: rows r, u, -f.
    double view[4][4] = {{r[0], r[1], r[2], -dot(r, e)},
                         {u[0], u[1], u[2], -dot(u, e)},
                         {-f[0], -f[1], -f[2], dot(f, e)},
                         {0, 0, 0, 1}};
    const double aspect = static_cast<double>(c.width_px) / c.height_px;
    const double tan_half_h = std::tan(c.horizontal_fov_deg * M_PI / 360.0);
    const double tan_half_v = tan_half_h / aspect;
    const double n = c.near_m, fa = c.far_m;
    double projection[4][4] = {{1.0 / tan_half_h, 0, 0, 0},
                               {0, 1.0 / tan_half_v, 0, 0},
                               {0, 0, -(fa + n) / (fa - n), -2.0 * fa * n / (fa - n)},
                               {0, 0, -1, 0}};
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row) {
        double sum = 0.0;
        for (int k = 0; k < 4; ++k) sum += projection[row][k] * view[k][col];
        out[col * 4 + row] = static_cast<float>(sum);
      }
    }
  }

  GLuint program_ = 0, vao_ = 0, vbo_ = 0, texture_ = 0;
  uint64_t uploaded_id_ = 0, uploaded_atlas_id_ = 0;
  size_t uploaded_vertices_ = 0;
  bool atlas_uploaded_ = false;
};

}  // namespace

StatusOr<std::unique_ptr<ViewRenderer>> CreateOsMesaViewRenderer() {
  auto renderer = std::make_unique<OsMesaViewRenderer>();
  Status status = renderer->Init();
  if (!status.ok()) return status;
  return std::unique_ptr<ViewRenderer>(std::move(renderer));
}

StatusOr<std::unique_ptr<SceneRenderer>> CreateOsMesaRenderer() {
  auto renderer = std::make_unique<OsMesaRenderer>();
  Status status = renderer->Init();
  if (!status.ok()) return status;
  return std::unique_ptr<SceneRenderer>(std::move(renderer));
}

Status RenderToPng(const Scene& scene, const std::string& path) {
  StatusOr<std::unique_ptr<SceneRenderer>> renderer = CreateOsMesaRenderer();
  if (!renderer.ok()) return renderer.status();
  StatusOr<RgbaImage> image = renderer.value()->Render(scene);
  if (!image.ok()) return image.status();
  return WritePng(image.value(), path);
}

}  // namespace ratslam::render
