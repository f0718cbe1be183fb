// Software rendering of triangle meshes to an image: no GUI, no GPU. Used for map previews
// (model and polycube side by side with the same checkerboard) and piece colourings.
#pragma once

#include "formats/image_io.h"
#include "polycube/mesh.h"

#include <Eigen/Core>

#include <vector>

namespace polycube {

// One mesh in one tile of the picture, with how to colour it.
struct RenderItem {
  const TriMesh* mesh = nullptr;
  // Colour source, the first one set wins:
  //   checker_coords  #V by 3 points; the surface gets a 3D checkerboard of these coordinates
  //                   (cells of checker_size), interpolated per pixel, so a map carries the
  //                   polycube's checkers onto the model
  //   face_rgb        #F by 3 in [0,1]
  //   otherwise       a light grey
  const Eigen::MatrixX3d* checker_coords = nullptr;
  double checker_size = 0.1;
  const Eigen::MatrixX3d* face_rgb = nullptr;
  // Flat shading shows the facets (right for polycubes); smooth shading interpolates normals.
  bool smooth = true;
  // Direction the camera looks along (towards the object); the default is a 3/4 view from the
  // front-right, above.
  Eigen::Vector3d view_direction{-1.0, 1.6, -0.9};
};

struct RenderOptions {
  int tile_width = 640;   // pixels per tile; tiles are side by side
  int tile_height = 640;
  int supersampling = 2;  // samples per pixel per axis, averaged
  Eigen::Vector3d up{0, 0, 1};
  // Draw every tile at the scale of the largest item, so sizes compare across tiles (a model and
  // its polycube); false frames each item to fill its own tile.
  bool same_scale = false;
  Eigen::Vector3d background{1, 1, 1};
};

// A light colour per index, neighbouring indices far apart in hue (golden-ratio steps); RGB in
// [0, 1]. For colouring pieces, patches, quads.
Eigen::Vector3d distinct_colour(int index);

// Renders each item into its own tile, left to right, each framed to fill its tile
// (orthographic projection). Returns an RGB image.
Image render_tiles(const std::vector<RenderItem>& items, const RenderOptions& options = {});

}  // namespace polycube
