// Geometry images and normal maps as OpenEXR files: one part (subimage) per patch, each a tiled MIP pyramid
// with ROUND_UP level sizes, so MIP level l of a (2^n+1)² grid is exactly (2^(n−l)+1)² texels and holds the
// nested grid of uniform level n−l (every 2^l-th sample, no filtering). The last level, n+1, is 1×1 and holds
// sample (0,0) (ROUND_UP pyramids always end at 1×1; every 2^(n+1)-th sample is just that one).
//
// Pixel (x, y) of a level is sample (i, j) = (x, y) (x along u, y along v; viewers draw v downward).
// Channels R, G, B = x, y, z (positions, float32) or the unit normal (half, for normal maps).
// Header attributes of every part (readable by `exrheader` and `oiiotool --info -v`):
//   geomip:kind           string  "geometry" or "normals"
//   geomip:source_mesh    string  the file name (no directory) of the mesh the images were resampled from
//   geomip:level          int     n, the finest grid level (part size 2^n+1)
//   geomip:patch          int     this part's patch index (the part is also named "patch<k>")
//   geomip:patches        int     number of patches
//   geomip:adjacency      string  the SideLinks, one "p.s-q.t" per (patch, side) in order, "r" appended when
//                                 reversed, space-separated: side s of patch p is glued to side t of patch q
//   geomip:normalization  m44d    the transform applied to the positions before storing (row-major, points
//                                 as row vectors as in Imath); identity when not normalized
// The library hides OpenEXR: nothing of it appears here. (Files are plain OpenEXR 2 multipart: oiiotool,
// exrheader, Blender and other EXR readers open them.)
#pragma once

#include "gimage/resample.h"
#include "param/mesh_partition.h"

#include <array>
#include <string>
#include <vector>

namespace geomip {

/// What the header attributes carry.
struct GeometryImageFileInfo {
  std::string kind = "geometry";  ///< "geometry" or "normals"
  std::string source_mesh;
  int level = 0;  ///< set by the writer from the images
  std::array<double, 16> normalization{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  std::vector<SideLink> adjacency;
};

struct ExrWriteOptions {
  bool half = false;   ///< channels as half (normal maps) instead of float32 (positions)
  int tile_size = 64;  ///< square tiles of tile_size² texels
};

/// Writes `patches` (all of one level) to `path` as a multipart tiled EXR with one MIP pyramid per patch (see
/// the file comment). `info.level` is taken from the images. Written to `path + ".tmp-<pid>"` and renamed
/// over `path`; on failure the temporary file is removed and `path` is untouched. \throw InvalidInput when
/// `patches` is empty, the images' levels differ or their sizes are wrong. `info.adjacency` is written as
/// given (read_geometry_image_exr() checks it). \throw IoError when the file cannot be written (OpenEXR's
/// message included).
void write_geometry_image_exr(const std::string& path, const std::vector<GeometryImage>& patches,
                              const GeometryImageFileInfo& info, const ExrWriteOptions& options = {});

/// One MIP level of one part as read: width × height texels, 3 floats each, row-major.
struct ExrMipLevel {
  int width = 0, height = 0;
  std::vector<float> rgb;
};

struct GeometryImageFile {
  GeometryImageFileInfo info;
  std::vector<std::vector<ExrMipLevel>> parts;  ///< per part (patch), per MIP level, finest first
  std::vector<std::string> part_names;
};

/// Reads every part and every MIP level of a file written by write_geometry_image_exr() (or any multipart
/// EXR whose parts have channels R, G, B: tiled parts give every MIP level, scanline parts one level).
/// Attributes that are absent keep GeometryImageFileInfo's defaults. No level larger than a
/// level-kMaxGeometryImageLevel image is allocated.
/// \throw InvalidInput (the user's file: exit 2 in the tools) when the file is missing, not a regular file,
/// not
///   an EXR or cannot be read (OpenEXR's message included: truncated or garbage bytes), holds no image, a
///   part's channels are not R, G, B, a level is larger than that bound, or the adjacency attribute is
///   malformed or does not glue the parts into a closed surface (check_adjacency()).
GeometryImageFile read_geometry_image_exr(const std::string& path);

/// The finest MIP level of every part of `file` as GeometryImages (what write_geometry_image_exr() wrote).
/// \throw InvalidInput when the file's level n is outside [0, kMaxGeometryImageLevel] or a part's finest
/// level is not square of size 2^n + 1 (the message names both sizes).
std::vector<GeometryImage> finest_grids(const GeometryImageFile& file);

/// The nested grid of `image` at a coarser level: every 2^(image.level − level)-th sample.
/// \throw InvalidInput when level is negative or above image.level.
GeometryImage nested_grid(const GeometryImage& image, int level);

/// The adjacency attribute's text form and back (see the file comment).
std::string adjacency_to_text(const std::vector<SideLink>& adjacency);
/// \throw InvalidInput when `text` is not a list of "p.s-q.t[r]" entries.
std::vector<SideLink> adjacency_from_text(const std::string& text);
/// Checks that `links` glue `num_patches` quad patches into a closed surface as the writer stores them: one
/// link per (patch, side) in order, each to a side of another place that links back to it in the same
/// direction. \throw InvalidInput saying which side is wrong.
void check_adjacency(const std::vector<SideLink>& links, int num_patches);

}  // namespace geomip
