#include "gimage/exr_io.h"

#include "param/errors.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfTileDescription.h>
#include <OpenEXR/ImfTiledOutputPart.h>
#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <filesystem>
#include <sstream>
#include <system_error>

namespace geomip {
namespace {

// The texels of MIP level `l` of `image`: every 2^l-th sample (the nested grid), `width` per row.
template <typename T>
std::vector<T> level_texels(const GeometryImage& image, int l, int width, int height) {
  std::vector<T> texels(3 * static_cast<std::size_t>(width) * height);
  const int step = 1 << l;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const float* s = image.at(x * step, y * step);
      T* d = texels.data() + 3 * (static_cast<std::size_t>(y) * width + x);
      for (int c = 0; c < 3; ++c) d[c] = T(s[c]);
    }
  }
  return texels;
}

void write_parts(const std::string& file_path, const std::vector<GeometryImage>& patches,
                 const GeometryImageFileInfo& info, const ExrWriteOptions& options) {
  const int level = patches[0].level;
  const int size = patches[0].size();
  const Imf::PixelType type = options.half ? Imf::HALF : Imf::FLOAT;
  const std::string adjacency = adjacency_to_text(info.adjacency);
  Imath::M44d normalization;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) normalization[r][c] = info.normalization[4 * r + c];
  }
  std::vector<Imf::Header> headers;
  for (std::size_t p = 0; p < patches.size(); ++p) {
    Imf::Header h(size, size);
    h.setTileDescription(
        Imf::TileDescription(options.tile_size, options.tile_size, Imf::MIPMAP_LEVELS, Imf::ROUND_UP));
    for (const char* c : {"R", "G", "B"}) h.channels().insert(c, Imf::Channel(type));
    h.setName("patch" + std::to_string(p));
    h.setType(Imf::TILEDIMAGE);
    h.insert("geomip:kind", Imf::StringAttribute(info.kind));
    h.insert("geomip:source_mesh", Imf::StringAttribute(info.source_mesh));
    h.insert("geomip:level", Imf::IntAttribute(level));
    h.insert("geomip:patch", Imf::IntAttribute(static_cast<int>(p)));
    h.insert("geomip:patches", Imf::IntAttribute(static_cast<int>(patches.size())));
    h.insert("geomip:adjacency", Imf::StringAttribute(adjacency));
    h.insert("geomip:normalization", Imf::M44dAttribute(normalization));
    headers.push_back(h);
  }
  Imf::MultiPartOutputFile file(file_path.c_str(), headers.data(), static_cast<int>(headers.size()));
  for (std::size_t p = 0; p < patches.size(); ++p) {
    Imf::TiledOutputPart part(file, static_cast<int>(p));
    for (int l = 0; l < part.numLevels(); ++l) {
      const int w = part.levelWidth(l), hgt = part.levelHeight(l);
      const int expected = l <= level ? (1 << (level - l)) + 1 : 1;
      if (w != expected || hgt != expected) {
        throw SolverFailure("write_geometry_image_exr: OpenEXR level " + std::to_string(l) + " is " +
                            std::to_string(w) + " wide, expected " + std::to_string(expected));
      }
      const std::size_t texel = 3 * (options.half ? sizeof(half) : sizeof(float));
      std::vector<float> f;
      std::vector<half> hf;
      char* base;
      if (options.half) {
        hf = level_texels<half>(patches[p], l, w, hgt);
        base = reinterpret_cast<char*>(hf.data());
      } else {
        f = level_texels<float>(patches[p], l, w, hgt);
        base = reinterpret_cast<char*>(f.data());
      }
      const std::size_t channel = options.half ? sizeof(half) : sizeof(float);
      Imf::FrameBuffer fb;
      fb.insert("R", Imf::Slice(type, base, texel, texel * w));
      fb.insert("G", Imf::Slice(type, base + channel, texel, texel * w));
      fb.insert("B", Imf::Slice(type, base + 2 * channel, texel, texel * w));
      part.setFrameBuffer(fb);
      part.writeTiles(0, part.numXTiles(l) - 1, 0, part.numYTiles(l) - 1, l);
    }
  }
}

}  // namespace

std::string adjacency_to_text(const std::vector<SideLink>& adjacency) {
  std::ostringstream out;
  for (std::size_t k = 0; k < adjacency.size(); ++k) {
    const SideLink& a = adjacency[k];
    if (k) out << ' ';
    out << a.patch << '.' << a.side << '-' << a.other_patch << '.' << a.other_side << (a.reversed ? "r" : "");
  }
  return out.str();
}

std::vector<SideLink> adjacency_from_text(const std::string& text) {
  std::vector<SideLink> links;
  std::istringstream in(text);
  std::string token;
  while (in >> token) {
    SideLink a{};
    char dot1 = 0, dash = 0, dot2 = 0;
    std::istringstream t(token);
    if (!(t >> a.patch >> dot1 >> a.side >> dash >> a.other_patch >> dot2 >> a.other_side) || dot1 != '.' ||
        dash != '-' || dot2 != '.') {
      throw InvalidInput("adjacency_from_text: malformed entry '" + token + "'");
    }
    std::string rest;
    t >> rest;
    if (rest != "" && rest != "r") throw InvalidInput("adjacency_from_text: malformed entry '" + token + "'");
    a.reversed = rest == "r";
    links.push_back(a);
  }
  return links;
}

std::vector<GeometryImage> finest_grids(const GeometryImageFile& file) {
  std::vector<GeometryImage> grids;
  for (std::size_t p = 0; p < file.parts.size(); ++p) {
    GeometryImage g;
    g.level = file.info.level;
    if (g.level < 0 || g.level > kMaxGeometryImageLevel || file.parts[p].empty() ||
        file.parts[p][0].width != g.size() || file.parts[p][0].height != g.size()) {
      throw InvalidInput("finest_grids: part " + std::to_string(p) + " is not a (2^" +
                         std::to_string(g.level) + "+1)² grid");
    }
    g.values = file.parts[p][0].rgb;
    grids.push_back(std::move(g));
  }
  return grids;
}

GeometryImage nested_grid(const GeometryImage& image, int level) {
  if (level < 0 || level > image.level) {
    throw InvalidInput("nested_grid: level " + std::to_string(level) + " is outside [0, " +
                       std::to_string(image.level) + "]");
  }
  GeometryImage out;
  out.level = level;
  out.values = level_texels<float>(image, image.level - level, out.size(), out.size());
  return out;
}

void write_geometry_image_exr(const std::string& path, const std::vector<GeometryImage>& patches,
                              const GeometryImageFileInfo& info, const ExrWriteOptions& options) {
  if (patches.empty()) throw InvalidInput("write_geometry_image_exr: no patches to write to " + path);
  for (const auto& p : patches) {
    if (p.level != patches[0].level || p.level < 0 ||
        p.values.size() != 3 * static_cast<std::size_t>(p.size()) * p.size()) {
      throw InvalidInput("write_geometry_image_exr: patches of different levels or wrong sizes for " + path);
    }
  }
  if (options.tile_size < 1) throw InvalidInput("write_geometry_image_exr: tile size must be positive");
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  try {
    write_parts(tmp, patches, info, options);
    std::filesystem::rename(tmp, path);
  } catch (const Error&) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw;
  } catch (const std::exception& e) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw IoError("write_geometry_image_exr: " + path + ": " + e.what());
  }
}

GeometryImageFile read_geometry_image_exr(const std::string& path) {
  auto in = OIIO::ImageInput::open(path);
  if (!in) throw IoError("read_geometry_image_exr: " + path + ": " + OIIO::geterror());
  GeometryImageFile file;
  for (int s = 0; in->seek_subimage(s, 0); ++s) {
    if (s == 0) {
      const OIIO::ImageSpec& spec = in->spec();
      file.info.kind = spec.get_string_attribute("geomip:kind", file.info.kind);
      file.info.source_mesh = spec.get_string_attribute("geomip:source_mesh");
      file.info.level = spec.get_int_attribute("geomip:level", 0);
      file.info.adjacency = adjacency_from_text(spec.get_string_attribute("geomip:adjacency"));
      if (const OIIO::ParamValue* m = spec.find_attribute("geomip:normalization")) {
        if (m->type() == OIIO::TypeDesc(OIIO::TypeDesc::DOUBLE, OIIO::TypeDesc::MATRIX44)) {
          const double* d = static_cast<const double*>(m->data());
          std::copy(d, d + 16, file.info.normalization.begin());
        } else if (m->type() == OIIO::TypeMatrix44) {
          const float* d = static_cast<const float*>(m->data());
          std::copy(d, d + 16, file.info.normalization.begin());
        }
      }
    }
    file.part_names.push_back(in->spec().get_string_attribute("oiio:subimagename"));
    std::vector<ExrMipLevel> levels;
    for (int m = 0; in->seek_subimage(s, m); ++m) {
      const OIIO::ImageSpec& spec = in->spec();
      if (spec.nchannels != 3) {
        throw InvalidInput("read_geometry_image_exr: " + path + ": part " + std::to_string(s) + " has " +
                           std::to_string(spec.nchannels) + " channels, expected 3");
      }
      ExrMipLevel level;
      level.width = spec.width;
      level.height = spec.height;
      level.rgb.resize(3 * static_cast<std::size_t>(spec.width) * spec.height);
      if (!in->read_image(s, m, 0, 3, OIIO::TypeDesc::FLOAT, level.rgb.data())) {
        throw IoError("read_geometry_image_exr: " + path + ": " + in->geterror());
      }
      levels.push_back(std::move(level));
    }
    file.parts.push_back(std::move(levels));
  }
  if (file.parts.empty()) throw IoError("read_geometry_image_exr: " + path + ": no image in the file");
  return file;
}

}  // namespace geomip
