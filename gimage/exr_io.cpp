#include "gimage/exr_io.h"

#include "mesh/errors.h"

#include <Imath/half.h>
#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputPart.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfMultiPartInputFile.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfTileDescription.h>
#include <OpenEXR/ImfTiledInputPart.h>
#include <OpenEXR/ImfTiledOutputPart.h>
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
      throw InvalidInput("malformed entry '" + token + "' (expected p.s-q.t or p.s-q.tr)");
    }
    std::string rest;
    t >> rest;
    if (rest != "" && rest != "r")
      throw InvalidInput("malformed entry '" + token + "' (expected p.s-q.t or p.s-q.tr)");
    a.reversed = rest == "r";
    links.push_back(a);
  }
  return links;
}

void check_adjacency(const std::vector<SideLink>& links, int num_patches) {
  if (num_patches < 1 || links.size() != 4 * static_cast<std::size_t>(num_patches))
    throw InvalidInput(std::to_string(links.size()) + " side links for " + std::to_string(num_patches) +
                       " patches (one per side: " + std::to_string(4LL * num_patches) + ")");
  auto name = [](int p, int s) { return std::to_string(p) + "." + std::to_string(s); };
  for (std::size_t k = 0; k < links.size(); ++k) {
    const SideLink& a = links[k];
    const int p = static_cast<int>(k / 4), s = static_cast<int>(k % 4);
    if (a.patch != p || a.side != s)
      throw InvalidInput("entry " + std::to_string(k) + " is for side " + name(a.patch, a.side) + ", not " +
                         name(p, s) + " (one entry per side, in order)");
    if (a.other_patch < 0 || a.other_patch >= num_patches || a.other_side < 0 || a.other_side > 3)
      throw InvalidInput("side " + name(p, s) + " is glued to " + name(a.other_patch, a.other_side) +
                         ", which is not a side of one of the " + std::to_string(num_patches) + " patches");
    if (a.other_patch == p && a.other_side == s)
      throw InvalidInput("side " + name(p, s) + " is glued to itself");
    const SideLink& b = links[4 * static_cast<std::size_t>(a.other_patch) + a.other_side];
    if (b.other_patch != p || b.other_side != s || b.reversed != a.reversed)
      throw InvalidInput("side " + name(p, s) + " is glued to " + name(a.other_patch, a.other_side) +
                         ", which is glued to " + name(b.other_patch, b.other_side) +
                         (b.reversed != a.reversed ? " in the other direction" : ""));
  }
}

std::vector<GeometryImage> finest_grids(const GeometryImageFile& file) {
  std::vector<GeometryImage> grids;
  for (std::size_t p = 0; p < file.parts.size(); ++p) {
    GeometryImage g;
    g.level = file.info.level;
    if (g.level < 0 || g.level > kMaxGeometryImageLevel)
      throw InvalidInput("geomip:level " + std::to_string(g.level) + " is outside [0, " +
                         std::to_string(kMaxGeometryImageLevel) + "]");
    if (file.parts[p].empty() || file.parts[p][0].width != g.size() || file.parts[p][0].height != g.size()) {
      // Name what the file holds: an EXR of another tool has no geomip:level (0 then), a crafted one a wrong
      // one.
      const std::string texels = file.parts[p].empty()
                                     ? std::string("empty")
                                     : std::to_string(file.parts[p][0].width) + "×" +
                                           std::to_string(file.parts[p][0].height) + " texels";
      throw InvalidInput("part " + std::to_string(p) + " is " + texels + ", but the file's geomip:level " +
                         std::to_string(g.level) + " needs (2^" + std::to_string(g.level) +
                         "+1)² = " + std::to_string(g.size()) + "×" + std::to_string(g.size()) +
                         " (not a geometry image written by geomip gimage?)");
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
  // OpenEXR directly (no OpenImageIO: linking it costs every geomip command ~1 s of start-up). Every size is
  // checked before anything is allocated: a crafted header cannot make this allocate more than its claim of
  // at most kMaxTexels texels per level.
  constexpr long long kMaxSide = (1 << kMaxGeometryImageLevel) + 1;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InvalidInput(path + ": " +
                       (std::filesystem::exists(path, ec) ? "not a regular file" : "no such file"));
  }
  GeometryImageFile file;
  try {
    Imf::MultiPartInputFile in(path.c_str());
    for (int s = 0; s < in.parts(); ++s) {
      const Imf::Header& h = in.header(s);
      if (s == 0) {
        if (const auto* a = h.findTypedAttribute<Imf::StringAttribute>("geomip:kind")) file.info.kind = a->value();
        if (const auto* a = h.findTypedAttribute<Imf::StringAttribute>("geomip:source_mesh"))
          file.info.source_mesh = a->value();
        if (const auto* a = h.findTypedAttribute<Imf::IntAttribute>("geomip:level")) file.info.level = a->value();
        if (const auto* a = h.findTypedAttribute<Imf::StringAttribute>("geomip:adjacency")) {
          try {
            file.info.adjacency = adjacency_from_text(a->value());
          } catch (const InvalidInput& e) {
            throw InvalidInput(path + ": geomip:adjacency: " + e.what());
          }
        }
        if (const auto* a = h.findTypedAttribute<Imf::M44dAttribute>("geomip:normalization")) {
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) file.info.normalization[4 * r + c] = a->value()[r][c];
        } else if (const auto* f = h.findTypedAttribute<Imf::M44fAttribute>("geomip:normalization")) {
          for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 4; ++c) file.info.normalization[4 * r + c] = f->value()[r][c];
        }
      }
      file.part_names.push_back(h.hasName() ? h.name() : std::string());
      int channels = 0;
      for (auto c = h.channels().begin(); c != h.channels().end(); ++c) ++channels;
      if (channels != 3 || !h.channels().findChannel("R") || !h.channels().findChannel("G") ||
          !h.channels().findChannel("B")) {
        throw InvalidInput(path + ": part " + std::to_string(s) + " has " + std::to_string(channels) +
                           " channels, expected R, G, B");
      }
      auto read_level = [&](const Imath::Box2i& window, auto&& read) {
        const long long w = 1LL + window.max.x - window.min.x, hgt = 1LL + window.max.y - window.min.y;
        if (w < 1 || hgt < 1 || w > kMaxSide || hgt > kMaxSide) {
          throw InvalidInput(path + ": part " + std::to_string(s) + " is " + std::to_string(w) + "×" +
                             std::to_string(hgt) + " texels, more than a level-" +
                             std::to_string(kMaxGeometryImageLevel) + " geometry image");
        }
        ExrMipLevel level;
        level.width = static_cast<int>(w);
        level.height = static_cast<int>(hgt);
        level.rgb.resize(3 * static_cast<std::size_t>(w) * hgt);
        // The frame buffer is addressed in data-window coordinates: shift the base so (min.x, min.y) is texel 0.
        char* base = reinterpret_cast<char*>(level.rgb.data()) -
                     (static_cast<std::ptrdiff_t>(window.min.y) * w + window.min.x) * 3 * sizeof(float);
        const std::size_t texel = 3 * sizeof(float);
        Imf::FrameBuffer fb;
        fb.insert("R", Imf::Slice(Imf::FLOAT, base, texel, texel * w));
        fb.insert("G", Imf::Slice(Imf::FLOAT, base + sizeof(float), texel, texel * w));
        fb.insert("B", Imf::Slice(Imf::FLOAT, base + 2 * sizeof(float), texel, texel * w));
        read(fb);
        return level;
      };
      std::vector<ExrMipLevel> levels;
      if (h.hasTileDescription() && (h.type() == Imf::TILEDIMAGE || !h.hasType())) {
        Imf::TiledInputPart part(in, s);
        const int num_levels = part.levelMode() == Imf::RIPMAP_LEVELS ? part.numXLevels() : part.numLevels();
        for (int l = 0; l < num_levels; ++l) {
          const Imath::Box2i window = part.dataWindowForLevel(l, l);
          levels.push_back(read_level(window, [&](Imf::FrameBuffer& fb) {
            part.setFrameBuffer(fb);
            part.readTiles(0, part.numXTiles(l) - 1, 0, part.numYTiles(l) - 1, l, l);
          }));
        }
      } else {
        Imf::InputPart part(in, s);
        const Imath::Box2i window = h.dataWindow();
        levels.push_back(read_level(window, [&](Imf::FrameBuffer& fb) {
          part.setFrameBuffer(fb);
          part.readPixels(window.min.y, window.max.y);
        }));
      }
      file.parts.push_back(std::move(levels));
    }
  } catch (const Error&) {
    throw;
  } catch (const std::exception& e) {  // OpenEXR refusing the bytes: the file is not a readable EXR
    throw InvalidInput(path + ": not a readable EXR image (" + e.what() + ")");
  }
  if (file.parts.empty()) throw InvalidInput(path + ": no image in the file");
  if (!file.info.adjacency.empty()) {  // a crafted or edited file: the seams must glue the parts as a surface
    try {
      check_adjacency(file.info.adjacency, static_cast<int>(file.parts.size()));
    } catch (const InvalidInput& e) {
      throw InvalidInput(path + ": geomip:adjacency: " + e.what());
    }
  }
  return file;
}

}  // namespace geomip
