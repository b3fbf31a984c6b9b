// speculum_llvmpipe_bench: the llvmpipe side of the rasterizer's yardstick (the same
// triangles drawn with a depth test and two colour outputs, with 2 threads; the figures are
// in docs/performance.md).
//
// Draws a triangle mesh (binary little-endian PLY, as `speculum bench raster ... --write-ply`
// writes it) through OSMesa — gallium/llvmpipe in Debian's Mesa — into an offscreen FBO with
// a 32-bit float depth buffer (test LESS, no culling) and two colour attachments: R32UI gets
// gl_PrimitiveID + 1 (a visibility buffer) and RGBA16F the interpolated world position (a
// G-buffer channel; --attribute-format picks RGBA32F or RGBA8 instead). Each timed frame is
// clear + one indexed draw + glFinish, so it measures the same "triangles in, two render
// targets out" work as `speculum bench raster`.
//
// Standalone on purpose (no speculum libraries): it only needs libOSMesa.
#define GL_GLEXT_PROTOTYPES 1  // libOSMesa exports the whole GL API, so link to it directly
#include <GL/osmesa.h>
#include <GL/glext.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace {

[[noreturn]] void die(const std::string& msg) {
  std::fprintf(stderr, "speculum_llvmpipe_bench: %s\n", msg.c_str());
  std::exit(1);
}

using Vec3 = std::array<float, 3>;
using Mat4 = std::array<float, 16>;  // column-major, as glUniformMatrix4fv expects

struct Mesh {
  std::vector<float> positions;       // x,y,z per vertex
  std::vector<std::uint32_t> indices; // 3 per triangle
};

// ---- PLY --------------------------------------------------------------------
// Minimal reader for what speculum's write_ply emits: binary_little_endian 1.0, a vertex
// element whose properties are all float (x, y, z among them), then a face element with one
// "list uchar uint|int" property whose every entry has 3 indices. Anything else is an error.
Mesh read_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) die(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || line != "ply") die(path + ": not a PLY file (no 'ply' magic)");
  std::uint64_t vertex_count = 0, face_count = 0;
  std::vector<std::string> vertex_props;
  std::string current;  // element whose properties are being listed
  bool format_ok = false, face_list_ok = false;
  while (true) {
    if (!std::getline(in, line)) die(path + ": header has no end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "end_header") break;
    if (word == "comment" || word == "obj_info" || word.empty()) continue;
    if (word == "format") {
      std::string fmt, ver;
      ls >> fmt >> ver;
      if (fmt != "binary_little_endian") die(path + ": format '" + fmt + "' unsupported (need binary_little_endian)");
      format_ok = true;
    } else if (word == "element") {
      std::uint64_t n = 0;
      ls >> current >> n;
      if (!ls) die(path + ": bad element line '" + line + "'");
      if (current == "vertex") vertex_count = n;
      else if (current == "face") face_count = n;
      else die(path + ": unsupported element '" + current + "'");
    } else if (word == "property") {
      std::string type;
      ls >> type;
      if (current == "vertex") {
        std::string name;
        ls >> name;
        if (type != "float" && type != "float32") die(path + ": vertex property '" + name + "' is not float");
        vertex_props.push_back(name);
      } else if (current == "face") {
        std::string count_type, index_type;
        ls >> count_type >> index_type;
        if (type != "list" || (count_type != "uchar" && count_type != "uint8") ||
            (index_type != "uint" && index_type != "int" && index_type != "uint32" && index_type != "int32"))
          die(path + ": face property must be 'list uchar uint|int', got '" + line + "'");
        if (face_list_ok) die(path + ": face element has more than one property");
        face_list_ok = true;
      } else {
        die(path + ": property outside a vertex/face element");
      }
    } else {
      die(path + ": unexpected header line '" + line + "'");
    }
  }
  if (!format_ok) die(path + ": header has no format line");
  if (face_count > 0 && !face_list_ok) die(path + ": face element has no index list");
  const auto find = [&](const char* name) {
    const auto it = std::find(vertex_props.begin(), vertex_props.end(), name);
    if (it == vertex_props.end()) die(path + ": vertex has no '" + name + "' property");
    return std::size_t(it - vertex_props.begin());
  };
  const std::size_t ix = find("x"), iy = find("y"), iz = find("z");
  const std::size_t stride = vertex_props.size();
  if (vertex_count > std::numeric_limits<std::uint32_t>::max()) die(path + ": too many vertices");

  Mesh m;
  std::vector<float> raw(vertex_count * stride);
  in.read(reinterpret_cast<char*>(raw.data()), std::streamsize(raw.size() * sizeof(float)));
  if (!in) die(path + ": truncated vertex data");
  m.positions.resize(vertex_count * 3);
  for (std::uint64_t v = 0; v < vertex_count; ++v) {
    m.positions[3 * v + 0] = raw[v * stride + ix];
    m.positions[3 * v + 1] = raw[v * stride + iy];
    m.positions[3 * v + 2] = raw[v * stride + iz];
  }
  // Faces are 13 bytes each (count + 3 indices): read them all, then walk the bytes.
  std::vector<unsigned char> faces(face_count * 13);
  in.read(reinterpret_cast<char*>(faces.data()), std::streamsize(faces.size()));
  if (!in) die(path + ": truncated face data (or a face that is not a triangle)");
  m.indices.resize(face_count * 3);
  for (std::uint64_t f = 0; f < face_count; ++f) {
    const unsigned char* p = &faces[f * 13];
    if (p[0] != 3) die(path + ": face " + std::to_string(f) + " has " + std::to_string(p[0]) + " vertices, only triangles are supported");
    for (int k = 0; k < 3; ++k) {
      std::uint32_t idx;
      std::memcpy(&idx, p + 1 + 4 * k, 4);  // little-endian host assumed (x86)
      if (idx >= vertex_count) die(path + ": face " + std::to_string(f) + " index " + std::to_string(idx) + " out of range");
      m.indices[3 * f + k] = idx;
    }
  }
  if (face_count == 0) die(path + ": no faces");
  return m;
}

// ---- camera -----------------------------------------------------------------
// Right-handed view (camera looks down -Z) and OpenGL clip space, the same conventions as
// speculum's core/camera_rays.cpp (glm::lookAt / glm::perspective).
Vec3 sub(Vec3 a, Vec3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 cross(Vec3 a, Vec3 b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
float dot(Vec3 a, Vec3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
Vec3 normalize(Vec3 a) {
  const float l = std::sqrt(dot(a, a));
  return {a[0] / l, a[1] / l, a[2] / l};
}

Mat4 multiply(const Mat4& a, const Mat4& b) {
  Mat4 r{};
  for (int c = 0; c < 4; ++c)
    for (int row = 0; row < 4; ++row)
      for (int k = 0; k < 4; ++k) r[c * 4 + row] += a[k * 4 + row] * b[c * 4 + k];
  return r;
}

Mat4 look_at(Vec3 eye, Vec3 target, Vec3 up) {
  const Vec3 f = normalize(sub(target, eye));
  const Vec3 s = normalize(cross(f, up));
  const Vec3 u = cross(s, f);
  return {s[0], u[0], -f[0], 0, s[1], u[1], -f[1], 0, s[2], u[2], -f[2], 0,
          -dot(s, eye), -dot(u, eye), dot(f, eye), 1};
}

Mat4 perspective(float vfov_deg, float aspect, float znear, float zfar) {
  const float t = std::tan(vfov_deg * 3.14159265358979f / 360.0f);
  Mat4 m{};
  m[0] = 1.0f / (aspect * t);
  m[5] = 1.0f / t;
  m[10] = -(zfar + znear) / (zfar - znear);
  m[11] = -1.0f;
  m[14] = -2.0f * zfar * znear / (zfar - znear);
  return m;
}

// ---- options ----------------------------------------------------------------
struct Options {
  std::string mesh;
  int width = 1920, height = 1080, repeat = 10;
  Vec3 eye{0, 0, 5}, target{0, 0, 0}, up{0, 1, 0};
  float fov = 45.0f;
  float znear = 0.0f, zfar = 0.0f;  // 0: derived from the mesh bounds
  std::string attribute_format = "rgba16f";  // the second colour attachment
  std::string write_ids;  // the visibility attachment after the last frame, if set
  bool json = false;
};

void usage(FILE* to) {
  std::fprintf(to,
      "usage: speculum_llvmpipe_bench MESH.ply [options]\n"
      "Times clear + one indexed draw + glFinish of MESH in OSMesa (llvmpipe): depth test LESS\n"
      "(32F), no culling, two colour outputs (R32UI primitive id, RGBA16F position).\n"
      "  --width N --height N   target size (default 1920x1080)\n"
      "  --eye x,y,z            camera position (default 0,0,5)\n"
      "  --target x,y,z         point looked at (default 0,0,0)\n"
      "  --up x,y,z             up vector (default 0,1,0)\n"
      "  --fov DEG              vertical field of view (default 45)\n"
      "  --near Z --far Z       clip planes (default: from the mesh bounds seen from the eye)\n"
      "  --attribute-format F   second attachment: rgba16f (default), rgba32f or rgba8\n"
      "  --repeat K             timed frames after one warm-up (default 10)\n"
      "  --json                 print one JSON object\n"
      "  --write-ids FILE       also write the primitive id + 1 per pixel (0: nothing) as raw\n"
      "                         little-endian uint32, top row first (as speculum bench raster\n"
      "                         --write-ids), to compare the two rasterizers pixel by pixel\n"
      "llvmpipe's thread count is set by the environment variable LP_NUM_THREADS (unset: one per\n"
      "CPU), e.g. LP_NUM_THREADS=2 speculum_llvmpipe_bench mesh.ply --json\n"
      "Export a speculum workload and its camera with e.g.\n"
      "  speculum bench raster bench:spheres-room --repeat 1 --write-ply sr.ply\n"
      "  LP_NUM_THREADS=2 speculum_llvmpipe_bench sr.ply --eye 0,4.5,7.5 --target 0,0.5,-1 --fov 60 \\\n"
      "      --near 0.05 --far 100 --repeat 7 --json\n"
      "(the workloads' cameras are in apps/bench/bench_workloads.cpp)\n");
}

Vec3 parse_vec3(const std::string& flag, const std::string& s) {
  Vec3 v{};
  char tail = 0;
  if (std::sscanf(s.c_str(), "%f,%f,%f%c", &v[0], &v[1], &v[2], &tail) != 3)
    die(flag + ": expected x,y,z, got '" + s + "'");
  return v;
}

double parse_number(const std::string& flag, const std::string& s) {
  char* end = nullptr;
  const double d = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(d)) die(flag + ": expected a number, got '" + s + "'");
  return d;
}

int parse_int(const std::string& flag, const std::string& s, int lo, int hi) {
  const double d = parse_number(flag, s);
  if (d != std::floor(d) || d < lo || d > hi)
    die(flag + ": expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got '" + s + "'");
  return int(d);
}

Options parse_args(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) die(a + ": missing value");
      return argv[++i];
    };
    if (a == "-h" || a == "--help") { usage(stdout); std::exit(0); }
    else if (a == "--width") o.width = parse_int(a, value(), 1, 16384);
    else if (a == "--height") o.height = parse_int(a, value(), 1, 16384);
    else if (a == "--repeat") o.repeat = parse_int(a, value(), 1, 1000000);
    else if (a == "--eye") o.eye = parse_vec3(a, value());
    else if (a == "--target") o.target = parse_vec3(a, value());
    else if (a == "--up") o.up = parse_vec3(a, value());
    else if (a == "--fov") o.fov = float(parse_number(a, value()));
    else if (a == "--near") o.znear = float(parse_number(a, value()));
    else if (a == "--far") o.zfar = float(parse_number(a, value()));
    else if (a == "--attribute-format") o.attribute_format = value();
    else if (a == "--json") o.json = true;
    else if (a == "--write-ids") o.write_ids = value();
    else if (!a.empty() && a[0] == '-') die("unknown option '" + a + "' (see --help)");
    else if (o.mesh.empty()) o.mesh = a;
    else die("more than one mesh given ('" + o.mesh + "', '" + a + "')");
  }
  if (o.mesh.empty()) { usage(stderr); std::exit(2); }
  if (o.attribute_format != "rgba16f" && o.attribute_format != "rgba32f" && o.attribute_format != "rgba8")
    die("--attribute-format: expected rgba16f, rgba32f or rgba8, got '" + o.attribute_format + "'");
  if (!(o.fov > 0.0f && o.fov < 180.0f)) die("--fov: must be in (0, 180)");
  const Vec3 f = sub(o.target, o.eye);
  if (dot(f, f) == 0.0f) die("--eye and --target coincide");
  const Vec3 s = cross(f, o.up);
  if (dot(s, s) == 0.0f) die("--up is parallel to the view direction");
  return o;
}

// Clip planes when not given: far just beyond the farthest bounding-box corner, near a small
// fraction of it (or half the distance to the box when the eye is outside it), so nothing in
// view is clipped and a 32-bit float depth buffer keeps ample precision.
void default_clip_planes(const Mesh& m, Options& o) {
  Vec3 lo{+INFINITY, +INFINITY, +INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
  for (std::size_t v = 0; v < m.positions.size(); v += 3)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], m.positions[v + k]);
      hi[k] = std::max(hi[k], m.positions[v + k]);
    }
  float far2 = 0.0f, near2 = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const Vec3 corner{c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2]};
    const Vec3 d = sub(corner, o.eye);
    far2 = std::max(far2, dot(d, d));
  }
  for (int k = 0; k < 3; ++k) {  // squared distance from the eye to the box
    const float d = std::max({lo[k] - o.eye[k], 0.0f, o.eye[k] - hi[k]});
    near2 += d * d;
  }
  if (o.zfar <= 0.0f) o.zfar = 1.01f * std::sqrt(far2) + 1e-3f;
  if (o.znear <= 0.0f) o.znear = std::max(1e-4f * o.zfar, 0.5f * std::sqrt(near2));
  if (!(o.znear < o.zfar)) die("--near must be smaller than --far");
}

// ---- GL -----------------------------------------------------------------------
void check_gl(const char* what) {
  const GLenum e = glGetError();
  if (e != GL_NO_ERROR) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%04x", e);
    die(std::string("GL error ") + buf + " after " + what);
  }
}

GLuint compile(GLenum type, const char* src) {
  const GLuint s = glCreateShader(type);
  glShaderSource(s, 1, &src, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    char log[2048] = {};
    glGetShaderInfoLog(s, sizeof log, nullptr, log);
    for (char* c = log; *c; ++c) if (*c == '\n') *c = ' ';
    die(std::string("shader compile failed: ") + log);
  }
  return s;
}

const char* kVertexShader = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 view_projection;
out vec3 world_position;
void main() {
  world_position = position;
  gl_Position = view_projection * vec4(position, 1.0);
}
)";

// Output 0: which triangle (0 = background); output 1: an interpolated attribute.
const char* kFragmentShader = R"(#version 330 core
in vec3 world_position;
layout(location = 0) out uint primitive;
layout(location = 1) out vec4 position;
void main() {
  primitive = uint(gl_PrimitiveID) + 1u;
  position = vec4(world_position, 1.0);
}
)";

std::string json_escape(const char* s) {
  std::string r;
  for (; s && *s; ++s) {
    if (*s == '"' || *s == '\\') r += '\\';
    if (static_cast<unsigned char>(*s) >= 0x20) r += *s;
  }
  return r;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  Options o = parse_args(argc, argv);
  const Mesh mesh = read_ply(o.mesh);
  default_clip_planes(mesh, o);
  const std::size_t triangles = mesh.indices.size() / 3;

  // Core 3.3 first; Mesa's compatibility profile also runs "#version 330 core" shaders.
  const char* profile = "core";
  const int core_attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0,
                              OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                              OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
  OSMesaContext ctx = OSMesaCreateContextAttribs(core_attribs, nullptr);
  if (!ctx) {
    profile = "compatibility";
    const int compat_attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0,
                                  OSMESA_PROFILE, OSMESA_COMPAT_PROFILE,
                                  OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    ctx = OSMesaCreateContextAttribs(compat_attribs, nullptr);
  }
  if (!ctx) die("OSMesaCreateContextAttribs failed for GL 3.3 core and compatibility profiles");
  // OSMesa needs a client buffer to make the context current; all drawing goes to the FBO.
  std::vector<unsigned char> window(16 * 16 * 4);
  if (!OSMesaMakeCurrent(ctx, window.data(), GL_UNSIGNED_BYTE, 16, 16)) die("OSMesaMakeCurrent failed");
  const char* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const char* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));

  // Render targets: visibility (R32UI), attribute (RGBA16F unless asked otherwise), depth (32F).
  GLuint fbo = 0, rb[3] = {};
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glGenRenderbuffers(3, rb);
  const GLenum attribute_format = o.attribute_format == "rgba32f" ? GL_RGBA32F
                                  : o.attribute_format == "rgba8" ? GL_RGBA8 : GL_RGBA16F;
  const GLenum formats[3] = {GL_R32UI, attribute_format, GL_DEPTH_COMPONENT32F};
  const GLenum points[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_DEPTH_ATTACHMENT};
  for (int i = 0; i < 3; ++i) {
    glBindRenderbuffer(GL_RENDERBUFFER, rb[i]);
    glRenderbufferStorage(GL_RENDERBUFFER, formats[i], o.width, o.height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, points[i], GL_RENDERBUFFER, rb[i]);
  }
  const GLenum draw_buffers[2] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  glDrawBuffers(2, draw_buffers);
  check_gl("framebuffer setup");
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) die("framebuffer incomplete");

  // Static geometry, uploaded once (as speculum's bench keeps the scene resident).
  GLuint vao = 0, buffers[2] = {};
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(2, buffers);
  glBindBuffer(GL_ARRAY_BUFFER, buffers[0]);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(mesh.positions.size() * sizeof(float)), mesh.positions.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, buffers[1]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(mesh.indices.size() * sizeof(std::uint32_t)), mesh.indices.data(), GL_STATIC_DRAW);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glEnableVertexAttribArray(0);
  check_gl("buffer upload");

  const GLuint program = glCreateProgram();
  glAttachShader(program, compile(GL_VERTEX_SHADER, kVertexShader));
  glAttachShader(program, compile(GL_FRAGMENT_SHADER, kFragmentShader));
  glLinkProgram(program);
  GLint linked = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &linked);
  if (!linked) die("shader link failed");
  glUseProgram(program);
  const Mat4 vp = multiply(perspective(o.fov, float(o.width) / float(o.height), o.znear, o.zfar),
                           look_at(o.eye, o.target, o.up));
  glUniformMatrix4fv(glGetUniformLocation(program, "view_projection"), 1, GL_FALSE, vp.data());

  glViewport(0, 0, o.width, o.height);
  glDisable(GL_CULL_FACE);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  check_gl("state setup");

  // glClear with a float colour is undefined for the integer attachment: clear each
  // attachment with its typed glClearBuffer* call instead (same work, well defined).
  const GLuint clear_id[4] = {0, 0, 0, 0};
  const GLfloat clear_position[4] = {0, 0, 0, 0};
  const GLfloat clear_depth = 1.0f;
  const auto frame = [&] {
    glClearBufferuiv(GL_COLOR, 0, clear_id);
    glClearBufferfv(GL_COLOR, 1, clear_position);
    glClearBufferfv(GL_DEPTH, 0, &clear_depth);
    glDrawElements(GL_TRIANGLES, GLsizei(mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
    glFinish();
  };
  frame();  // warm-up: shader JIT, first touch of the render targets
  check_gl("warm-up frame");
  std::vector<double> frame_ms;
  for (int r = 0; r < o.repeat; ++r) {
    const auto t0 = std::chrono::steady_clock::now();
    frame();
    const auto t1 = std::chrono::steady_clock::now();
    frame_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  check_gl("timed frames");

  // Sanity (untimed): pixels whose visibility id is set; 0 means the camera saw nothing.
  std::vector<GLuint> ids(std::size_t(o.width) * o.height);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, o.width, o.height, GL_RED_INTEGER, GL_UNSIGNED_INT, ids.data());
  check_gl("glReadPixels");
  const std::size_t covered = std::size_t(std::count_if(ids.begin(), ids.end(), [](GLuint v) { return v != 0; }));
  if (!o.write_ids.empty()) {
    // GL's rows run bottom to top; the file's top to bottom.
    std::ofstream out(o.write_ids, std::ios::binary | std::ios::trunc);
    for (int y = o.height - 1; y >= 0; --y)
      out.write(reinterpret_cast<const char*>(ids.data() + std::size_t(y) * o.width),
                std::streamsize(std::size_t(o.width) * sizeof(GLuint)));
    if (!out) die(o.write_ids + ": cannot write");
  }

  // llvmpipe reads LP_NUM_THREADS once; unset, it uses one rasterizer thread per CPU.
  const char* env_threads = std::getenv("LP_NUM_THREADS");
  const int threads = env_threads ? std::atoi(env_threads) : int(std::thread::hardware_concurrency());
  const double med = median(frame_ms);
  const double lo = *std::min_element(frame_ms.begin(), frame_ms.end());
  const double hi = *std::max_element(frame_ms.begin(), frame_ms.end());
  const double pixels = double(o.width) * o.height;
  if (o.json) {
    std::printf("{\"mesh\": \"%s\", \"renderer\": \"%s\", \"gl_version\": \"%s\", \"profile\": \"%s\", "
                "\"triangles\": %zu, \"width\": %d, \"height\": %d, \"threads\": %d, "
                "\"threads_source\": \"%s\", \"attribute_format\": \"%s\", \"repeat\": %d, \"ms_median\": %.3f, \"ms_min\": %.3f, "
                "\"ms_max\": %.3f, \"mtris_per_s\": %.3f, \"covered_pixels\": %zu, "
                "\"covered_fraction\": %.4f, \"near\": %g, \"far\": %g}\n",
                json_escape(o.mesh.c_str()).c_str(), json_escape(renderer).c_str(),
                json_escape(version).c_str(), profile, triangles, o.width, o.height, threads,
                env_threads ? "LP_NUM_THREADS" : "default (one per CPU)", o.attribute_format.c_str(), o.repeat, med, lo, hi,
                triangles / (med * 1e-3) / 1e6, covered, covered / pixels, o.znear, o.zfar);
  } else {
    std::printf("%s on %s (%s profile, %d threads): %zu triangles at %dx%d: median %.2f ms "
                "(min %.2f, max %.2f), %.1f Mtris/s, %zu pixels covered (%.1f%%)\n",
                o.mesh.c_str(), renderer, profile, threads, triangles, o.width, o.height, med, lo, hi,
                triangles / (med * 1e-3) / 1e6, covered, 100.0 * covered / pixels);
  }
  OSMesaDestroyContext(ctx);
  return 0;
}
