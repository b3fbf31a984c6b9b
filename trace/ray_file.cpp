// SPRY ray files (see ray_file.h).
#include "trace/ray_file.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <vector>

#include "core/error.h"

namespace speculum::trace {

namespace {
constexpr char kMagic[4] = {'S', 'P', 'R', 'Y'};
constexpr std::uint32_t kVersion = 1;
static_assert(std::endian::native == std::endian::little, "SPRY I/O assumes a little-endian host");
}  // namespace

RayStream read_ray_file(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(path, "cannot read ray file (" + ec.message() + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open ray file");
  char magic[4];
  std::uint32_t version = 0;
  std::uint64_t count = 0;
  in.read(magic, 4);
  in.read(reinterpret_cast<char*>(&version), 4);
  in.read(reinterpret_cast<char*>(&count), 8);
  if (!in || size < 16) throw InputError(path, "truncated ray file header");
  if (std::memcmp(magic, kMagic, 4) != 0) throw InputError(path, "not a SPRY ray file (bad magic)");
  if (version != kVersion) throw InputError(path, "unsupported SPRY version " + std::to_string(version));
  if (count > (size - 16) / 32 || count * 32 != size - 16)
    throw InputError(path, "ray count " + std::to_string(count) + " does not match the file size");
  RayStream rays;
  rays.resize(count);
  constexpr std::size_t kBlock = 1 << 16;
  std::vector<float> buf(kBlock * 8);
  for (std::size_t done = 0; done < count;) {
    const std::size_t n = std::min<std::size_t>(kBlock, count - done);
    in.read(reinterpret_cast<char*>(buf.data()), static_cast<std::streamsize>(n * 32));
    if (!in) throw InputError(path, "truncated ray records");
    for (std::size_t i = 0; i < n; ++i) {
      const float* r = &buf[i * 8];
      const std::size_t k = done + i;
      rays.ox[k] = r[0]; rays.oy[k] = r[1]; rays.oz[k] = r[2]; rays.tmin[k] = r[3];
      rays.dx[k] = r[4]; rays.dy[k] = r[5]; rays.dz[k] = r[6]; rays.tmax[k] = r[7];
    }
    done += n;
  }
  return rays;
}

void write_ray_file(const std::string& path, const RayStream& rays) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(path, "cannot create ray file");
    const std::uint64_t count = rays.size();
    out.write(kMagic, 4);
    out.write(reinterpret_cast<const char*>(&kVersion), 4);
    out.write(reinterpret_cast<const char*>(&count), 8);
    std::vector<float> rec(8);
    for (std::size_t i = 0; i < rays.size(); ++i) {
      const float r[8] = {rays.ox[i], rays.oy[i], rays.oz[i], rays.tmin[i],
                          rays.dx[i], rays.dy[i], rays.dz[i], rays.tmax[i]};
      out.write(reinterpret_cast<const char*>(r), sizeof(r));
    }
    if (!out) {
      out.close();
      std::remove(tmp.c_str());
      throw InputError(path, "write failed");
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::remove(tmp.c_str());
    throw InputError(path, "cannot rename the finished ray file (" + ec.message() + ")");
  }
}

}  // namespace speculum::trace
