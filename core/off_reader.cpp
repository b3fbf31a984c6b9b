// See off_reader.h. Section names below are the Geomview manual's (OOGL file formats).
#include "core/off_reader.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <optional>

#include "core/error.h"
#include "core/scene_loader.h"

namespace speculum {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

// The header keyword's prefixes, "[ST][C][N][4][n]OFF" (OFF section).
struct Keyword {
  bool st = false, colour = false, normal = false, four = false, ndim = false;
};

std::optional<Keyword> parse_keyword(std::string_view t) {
  Keyword k;
  auto eat = [&](std::string_view p) {
    if (!t.starts_with(p)) return false;
    t.remove_prefix(p.size());
    return true;
  };
  k.st = eat("ST");
  k.colour = eat("C");
  k.normal = eat("N");
  k.four = eat("4");
  k.ndim = eat("n");
  if (t != "OFF") return std::nullopt;
  return k;
}

// A decimal number (C locale, like every OFF writer): the whole token or nothing. A value
// past a double's range is +-infinity (the caller rejects it as non-finite), one below its
// smallest subnormal is 0, as strtod rounds it.
std::optional<double> to_double(std::string_view t) {
  if (t.starts_with('+')) t.remove_prefix(1);
  if (t.empty()) return std::nullopt;
  double v = 0.0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ptr != t.data() + t.size()) return std::nullopt;
  if (r.ec == std::errc::result_out_of_range) {
    // from_chars reports overflow and underflow alike; strtod tells them apart. Tokens of a
    // valid number are short; longer ones are not numbers an OFF writer makes.
    if (t.size() > 400) return std::nullopt;
    char buf[401];
    std::memcpy(buf, t.data(), t.size());
    buf[t.size()] = '\0';
    return std::strtod(buf, nullptr);
  }
  if (r.ec != std::errc()) return std::nullopt;
  return v;
}

// A whole number, possibly negative, of at most 18 digits.
std::optional<long long> to_integer(std::string_view t) {
  if (t.starts_with('+')) t.remove_prefix(1);
  if (t.empty() || t.size() > 19) return std::nullopt;
  long long v = 0;
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return std::nullopt;
  return v;
}

// A value as shown in a message: its first 24 characters, any byte that is not printable
// ASCII as \xNN, so the message stays one line whatever the file holds.
std::string quoted(std::string_view t) {
  std::string out = "'";
  for (const char c : t.substr(0, 24)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7f) {
      out += c;
    } else {
      static const char* kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    }
  }
  return out + (t.size() > 24 ? "...'" : "'");
}

// The three values of a vertex position as floats, or a one-line error. 4OFF's homogeneous
// coordinate divides (OFF section: "a final homogeneous component"); w = 0 is a point at
// infinity, which no triangle can use.
glm::vec3 finite_position(const std::string& path, std::uint64_t i, const std::array<double, 4>& v, bool four) {
  double x = v[0], y = v[1], z = v[2];
  if (four) {
    x /= v[3];
    y /= v[3];
    z /= v[3];
  }
  constexpr double kMax = std::numeric_limits<float>::max();
  if (!(std::fabs(x) < kMax && std::fabs(y) < kMax && std::fabs(z) < kMax))
    throw InputError(path, "non-finite vertex " + std::to_string(i) +
                               " (a coordinate is NaN, infinite or overflows a float" +
                               (four ? ", or its homogeneous w is 0)" : ")"));
  return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
}

class Reader {
 public:
  Reader(const std::string& path, std::string_view bytes) : path_(path), s_(bytes) {}

  OffMesh read() {
    std::string_view first;
    if (!next(first)) throw InputError(path_, "file holds no OFF data (only white space or comments)");
    if (auto k = parse_keyword(first)) {
      key_ = *k;
      std::string_view t;
      if (next_on_line(t)) {
        if (t == "BINARY") return read_binary();
        pending_ = t;  // counts on the keyword's line: white space is free-form there
      }
    } else if (to_integer(first)) {
      pending_ = first;  // no keyword: "recommended but optional" (OFF section)
    } else if (first.find("OFF") != std::string_view::npos) {
      throw InputError(path_, "OFF header: " + quoted(first) + " is not an OFF keyword ([ST][C][N][4][n]OFF)");
    } else {
      throw InputError(path_, "missing OFF header (neither the OFF keyword nor a vertex count comes first)");
    }
    return read_ascii();
  }

 private:
  // ---- ASCII: values separated by white space, '#' comments to the end of a line ----
  void skip_space() {
    while (at_ < s_.size()) {
      if (s_[at_] == '#') {
        while (at_ < s_.size() && s_[at_] != '\n') ++at_;
      } else if (is_space(s_[at_])) {
        ++at_;
      } else {
        break;
      }
    }
  }
  std::string_view token() {
    const std::size_t b = at_;
    while (at_ < s_.size() && !is_space(s_[at_]) && s_[at_] != '#') ++at_;
    return s_.substr(b, at_ - b);
  }
  bool next(std::string_view& t) {
    if (pending_) {
      t = *pending_;
      pending_.reset();
      return true;
    }
    skip_space();
    if (at_ >= s_.size()) return false;
    t = token();
    return true;
  }
  // The next value on the current line only: a face's colour "begins after VERTN and ends with
  // the end of the line (or the next # comment)" (OFF section).
  bool next_on_line(std::string_view& t) {
    while (at_ < s_.size() && s_[at_] != '\n' && is_space(s_[at_])) ++at_;
    if (at_ >= s_.size() || s_[at_] == '\n' || s_[at_] == '#') return false;
    t = token();
    return true;
  }
  std::size_t left() const { return s_.size() - at_; }

  std::string_view need(const std::string& what) {
    std::string_view t;
    if (!next(t)) throw InputError(path_, "OFF data truncated: the file ends before " + what);
    return t;
  }
  std::uint64_t count(const char* what) {
    const std::string_view t = need(std::string("the ") + what);
    const auto v = to_integer(t);
    if (!v || *v < 0 || t.size() > 12)
      throw InputError(path_, std::string("OFF header: the ") + what + " " + quoted(t) + " is not a whole number below 10^12");
    return static_cast<std::uint64_t>(*v);
  }
  double number(const std::string& what) {
    const std::string_view t = need(what);
    const auto v = to_double(t);
    if (!v) throw InputError(path_, "OFF " + what + ": " + quoted(t) + " is not a number");
    return *v;
  }

  // Counts against the bytes left, before anything is reserved: each value takes at least one
  // character and one separator.
  void check_counts(std::uint64_t nv, std::uint64_t nf, std::uint64_t values_per_vertex, std::uint64_t bytes_per_value,
                    std::uint64_t min_face_bytes) const {
    const std::uint64_t bytes = left() + 1;  // the last value needs no separator
    if (nv > bytes / (values_per_vertex * bytes_per_value))
      throw InputError(path_, "header declares " + std::to_string(nv) + " vertices but the file has only " +
                                  std::to_string(s_.size()) + " bytes");
    if (nf > bytes / min_face_bytes)
      throw InputError(path_, "header declares " + std::to_string(nf) + " faces but the file has only " +
                                  std::to_string(s_.size()) + " bytes");
    if (nv > kMaxSceneVertices)
      throw InputError(path_, "header declares " + std::to_string(nv) + " vertices: more than the limit of " +
                                  std::to_string(kMaxSceneVertices) + " (2^25)");
  }

  // Ndim (nOFF) and the values of a position: only 3-D vertices can be rendered.
  int position_values(long long ndim) const {
    if (key_.ndim && ndim != 3)
      throw InputError(path_, "OFF: " + std::to_string(ndim) + "-dimensional vertices (nOFF) cannot be rendered, only 3-D ones");
    return key_.four ? 4 : 3;
  }

  // An empty mesh with room for nv vertices and the attributes the keyword declares.
  OffMesh vertex_storage(std::uint64_t nv) const {
    OffMesh m;
    m.positions.reserve(nv);
    if (key_.normal) m.normals.reserve(nv);
    if (key_.st) m.uvs.reserve(nv);
    return m;
  }

  // Vertex i's position (pv values, divided by w for 4OFF) and, for NOFF, its normal, read
  // with the format's number reader `value(label)`.
  template <class Read>
  void read_position_and_normal(OffMesh& m, std::uint64_t i, int pv, const std::string& what,
                                const std::string& normal_what, Read value) {
    std::array<double, 4> v{};
    for (int k = 0; k < pv; ++k) v[k] = value(what);
    m.positions.push_back(finite_position(path_, i, v, key_.four));
    if (key_.normal) {
      glm::vec3 n;
      for (int k = 0; k < 3; ++k) n[k] = static_cast<float>(value(normal_what));
      m.normals.push_back(n);
    }
  }

  OffMesh read_ascii() {
    const long long ndim = key_.ndim ? static_cast<long long>(count("dimension")) : 3;
    const int pv = position_values(ndim);
    const std::uint64_t nv = count("vertex count"), nf = count("face count");
    (void)count("edge count");  // "not used or checked ... but must be present"
    const std::uint64_t per_vertex = pv + (key_.normal ? 3 : 0) + (key_.st ? 2 : 0);
    check_counts(nv, nf, per_vertex, 2, 2);
    OffMesh m = vertex_storage(nv);
    for (std::uint64_t i = 0; i < nv; ++i) {
      const std::string what = "vertex " + std::to_string(i);
      read_position_and_normal(m, i, pv, what, what + " normal", [&](const std::string& w) { return number(w); });
      if (key_.colour) {
        // A colour's length is not fixed (1 index, 3 or 4 components), so it is what is left
        // on the vertex's line, less the texture coordinates that follow it.
        std::array<double, 6> rest{};
        std::size_t k = 0;
        for (std::string_view t; next_on_line(t); ++k) {
          const auto x = to_double(t);
          if (!x) throw InputError(path_, "OFF " + what + " colour: " + quoted(t) + " is not a number");
          if (k == rest.size())
            throw InputError(path_, "OFF " + what + ": more values on its line than a colour (4) and texture coordinates");
          rest[k] = *x;
        }
        if (key_.st) {
          if (k < 2) throw InputError(path_, "OFF " + what + ": its line ends before the texture coordinates");
          m.uvs.emplace_back(static_cast<float>(rest[k - 2]), static_cast<float>(rest[k - 1]));
          k -= 2;
        }
        if (k > 4) throw InputError(path_, "OFF " + what + ": more than 4 colour values");
      } else if (key_.st) {
        const float s = static_cast<float>(number(what + " texture coordinate"));
        m.uvs.emplace_back(s, static_cast<float>(number(what + " texture coordinate")));
      }
    }
    m.faces = nf;
    std::vector<std::uint32_t> corners;
    for (std::uint64_t f = 0; f < nf; ++f) {
      const std::string what = "face " + std::to_string(f);
      const std::string_view t = need(what + " (the header declares " + std::to_string(nf) + " faces)");
      const auto k = to_integer(t);
      if (!k) throw InputError(path_, "OFF " + what + ": corner count " + quoted(t) + " is not a whole number");
      if (*k < 0) throw InputError(path_, "OFF " + what + " has a negative corner count " + quoted(t));
      if (static_cast<std::uint64_t>(*k) > (left() + 1) / 2)
        throw InputError(path_, "OFF " + what + " claims " + std::to_string(*k) + " corners but the file holds only " +
                                    std::to_string(left()) + " more bytes");
      corners.clear();
      for (long long c = 0; c < *k; ++c) {
        const std::string_view it = need(what + "'s corners");
        const auto idx = to_integer(it);
        if (!idx) throw InputError(path_, "OFF " + what + ": vertex index " + quoted(it) + " is not a whole number");
        corners.push_back(checked_index(what, *idx, nv));
      }
      std::size_t colour = 0;
      for (std::string_view ct; next_on_line(ct); ++colour)
        if (!to_double(ct) || colour == 4)
          throw InputError(path_, "OFF " + what + ": " + quoted(ct) +
                                      " after its corners is not part of a colour (0 to 4 numbers to the end of the line)");
      add_face(m, corners);
    }
    return m;
  }

  // ---- BINARY: "32-bit integers and 32-bit IEEE-format floats, both in big-endian format"
  // (Binary format section); the data begin after the first newline that follows BINARY.
  std::uint32_t u32(const std::string& what) {
    if (left() < 4) throw InputError(path_, "binary OFF data truncated: the file ends before " + what);
    const auto* p = reinterpret_cast<const unsigned char*>(s_.data() + at_);
    at_ += 4;
    return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
  }
  std::int32_t i32(const std::string& what) { return static_cast<std::int32_t>(u32(what)); }
  float f32(const std::string& what) {
    const std::uint32_t b = u32(what);
    float f;
    std::memcpy(&f, &b, 4);
    return f;
  }
  std::uint64_t bcount(const char* what) {
    const std::int32_t v = i32(std::string("the ") + what);
    if (v < 0) throw InputError(path_, std::string("binary OFF header: the ") + what + " is negative");
    return static_cast<std::uint64_t>(v);
  }

  OffMesh read_binary() {
    const std::size_t nl = s_.find('\n', at_);
    if (nl == std::string_view::npos) throw InputError(path_, "binary OFF: no newline after BINARY");
    at_ = nl + 1;
    const long long ndim = key_.ndim ? static_cast<long long>(bcount("dimension")) : 3;
    const int pv = position_values(ndim);
    const std::uint64_t nv = bcount("vertex count"), nf = bcount("face count");
    (void)bcount("edge count");
    // A binary vertex colour is 4 floats (RGBA); a face is Nv, its indices, a colour count and
    // that many floats (OFF section, binary form).
    const std::uint64_t per_vertex = pv + (key_.normal ? 3 : 0) + (key_.colour ? 4 : 0) + (key_.st ? 2 : 0);
    check_counts(nv, nf, per_vertex, 4, 8);
    OffMesh m = vertex_storage(nv);
    for (std::uint64_t i = 0; i < nv; ++i) {
      const std::string what = "vertex " + std::to_string(i);
      read_position_and_normal(m, i, pv, what, what, [&](const std::string& w) { return double(f32(w)); });
      if (key_.colour)
        for (int k = 0; k < 4; ++k) (void)f32(what);
      if (key_.st) {
        const float s = f32(what);
        m.uvs.emplace_back(s, f32(what));
      }
    }
    m.faces = nf;
    std::vector<std::uint32_t> corners;
    for (std::uint64_t f = 0; f < nf; ++f) {
      const std::string what = "face " + std::to_string(f);
      const std::int32_t k = i32(what + " (the header declares " + std::to_string(nf) + " faces)");
      if (k < 0) throw InputError(path_, "OFF " + what + " has a negative corner count " + std::to_string(k));
      if (static_cast<std::uint64_t>(k) > left() / 4)
        throw InputError(path_, "OFF " + what + " claims " + std::to_string(k) + " corners but the file holds only " +
                                    std::to_string(left()) + " more bytes");
      corners.clear();
      for (std::int32_t c = 0; c < k; ++c) corners.push_back(checked_index(what, i32(what + "'s corners"), nv));
      const std::int32_t colours = i32(what + "'s colour count");
      if (colours < 0 || colours > 4)
        throw InputError(path_, "OFF " + what + ": colour count " + std::to_string(colours) + " is outside [0, 4]");
      for (std::int32_t c = 0; c < colours; ++c) (void)f32(what + "'s colour");
      add_face(m, corners);
    }
    return m;
  }

  // ---- both ----
  std::uint32_t checked_index(const std::string& what, long long idx, std::uint64_t nv) const {
    if (idx < 0 || static_cast<std::uint64_t>(idx) >= nv)
      throw InputError(path_, "OFF " + what + ": vertex index " + std::to_string(idx) + " is out of range (" +
                                  std::to_string(nv) + " vertices)");
    return static_cast<std::uint32_t>(idx);
  }

  // A polygon as a fan from its first corner (the polygons are planar, "may be concave": a fan
  // is exact for convex ones, as OpenMesh's triangle mesh does it). Fewer than 3 corners is no
  // polygon; a fan triangle that repeats a corner has no area. Both are counted and left out.
  void add_face(OffMesh& m, const std::vector<std::uint32_t>& c) {
    if (c.size() < 3) {
      ++m.short_faces;
      return;
    }
    for (std::size_t j = 1; j + 1 < c.size(); ++j) {
      if (c[0] == c[j] || c[j] == c[j + 1] || c[0] == c[j + 1]) {
        ++m.degenerate_triangles;
        continue;
      }
      if (m.indices.size() / 3 >= kMaxSceneTriangles)
        throw InputError(path_, "more than the limit of " + std::to_string(kMaxSceneTriangles) + " triangles (2^24)");
      m.indices.insert(m.indices.end(), {c[0], c[j], c[j + 1]});
    }
  }

  const std::string& path_;
  std::string_view s_;
  std::size_t at_ = 0;
  std::optional<std::string_view> pending_;
  Keyword key_;
};

}  // namespace

OffMesh read_off(const std::string& path, std::string_view bytes) { return Reader(path, bytes).read(); }

}  // namespace speculum
