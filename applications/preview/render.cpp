#include "applications/preview/render.h"

#include "polycube/errors.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <limits>

namespace polycube {

namespace {

// A pixel-space framing of one item: orthographic projection onto the view plane.
struct View {
  Eigen::Vector3d right, up, forward;
  double scale = 1, offset_x = 0, offset_y = 0;

  Eigen::Vector3d project(const Eigen::Vector3d& p) const {
    return {offset_x + scale * p.dot(right), offset_y - scale * p.dot(up), p.dot(forward)};
  }
};

// Frames the item to fill a width by height tile; with max_scale > 0 the scale is at most that.
View frame(const RenderItem& item, const RenderOptions& options, int width, int height, double max_scale = 0) {
  const TriMesh& mesh = *item.mesh;
  View view;
  view.forward = item.view_direction.normalized();
  view.right = view.forward.cross(options.up).normalized();
  view.up = view.right.cross(view.forward);
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d p = mesh.V.row(v);
    x0 = std::min(x0, p.dot(view.right));
    x1 = std::max(x1, p.dot(view.right));
    y0 = std::min(y0, p.dot(view.up));
    y1 = std::max(y1, p.dot(view.up));
  }
  const double margin = 0.92;
  const double span = std::max({x1 - x0, (y1 - y0) * width / static_cast<double>(height), 1e-300});
  view.scale = margin * width / span;
  if (max_scale > 0) view.scale = std::min(view.scale, max_scale);
  view.offset_x = 0.5 * width - view.scale * 0.5 * (x0 + x1);
  view.offset_y = 0.5 * height + view.scale * 0.5 * (y0 + y1);
  return view;
}

Eigen::MatrixX3d vertex_normals(const TriMesh& mesh) {
  Eigen::MatrixX3d normals = Eigen::MatrixX3d::Zero(mesh.num_vertices(), 3);
  for (int f = 0; f < mesh.num_faces(); ++f) {
    const Eigen::Vector3d a = mesh.V.row(mesh.F(f, 0)), b = mesh.V.row(mesh.F(f, 1)), c = mesh.V.row(mesh.F(f, 2));
    const Eigen::Vector3d n = (b - a).cross(c - a);  // area weighted
    for (int i = 0; i < 3; ++i) normals.row(mesh.F(f, i)) += n.transpose();
  }
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const double len = normals.row(v).norm();
    if (len > 0) normals.row(v) /= len;
  }
  return normals;
}

Eigen::Vector3d checker_colour(const Eigen::Vector3d& p, double size) {
  const long parity = static_cast<long>(std::floor(p.x() / size)) + static_cast<long>(std::floor(p.y() / size)) +
                      static_cast<long>(std::floor(p.z() / size));
  return (parity & 1) ? Eigen::Vector3d(0.93, 0.45, 0.12) : Eigen::Vector3d(0.97, 0.95, 0.90);
}

// Rasterises one item into a supersampled colour/depth buffer of w by h samples.
void rasterise(const RenderItem& item, const RenderOptions& options, int w, int h, double max_scale,
               std::vector<Eigen::Vector3f>& colour) {
  const TriMesh& mesh = *item.mesh;
  const View view = frame(item, options, w, h, max_scale);
  std::vector<Eigen::Vector3d> screen(mesh.num_vertices());
  for (int v = 0; v < mesh.num_vertices(); ++v) screen[v] = view.project(mesh.V.row(v).transpose());
  const Eigen::MatrixX3d normals = item.smooth ? vertex_normals(mesh) : Eigen::MatrixX3d();
  const Eigen::Vector3d light = (-view.forward + 0.6 * view.up - 0.35 * view.right).normalized();
  const Eigen::Vector3d fill = (-view.forward - 0.3 * view.up + 0.6 * view.right).normalized();
  std::vector<double> depth(static_cast<size_t>(w) * h, std::numeric_limits<double>::infinity());

  for (int f = 0; f < mesh.num_faces(); ++f) {
    const int i0 = mesh.F(f, 0), i1 = mesh.F(f, 1), i2 = mesh.F(f, 2);
    const Eigen::Vector3d &a = screen[i0], &b = screen[i1], &c = screen[i2];
    const double area = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
    if (area == 0) continue;
    const int x_lo = std::max(0, static_cast<int>(std::floor(std::min({a.x(), b.x(), c.x()}))));
    const int x_hi = std::min(w - 1, static_cast<int>(std::ceil(std::max({a.x(), b.x(), c.x()}))));
    const int y_lo = std::max(0, static_cast<int>(std::floor(std::min({a.y(), b.y(), c.y()}))));
    const int y_hi = std::min(h - 1, static_cast<int>(std::ceil(std::max({a.y(), b.y(), c.y()}))));
    const Eigen::Vector3d pa = mesh.V.row(i0), pb = mesh.V.row(i1), pc = mesh.V.row(i2);
    const Eigen::Vector3d face_normal = (pb - pa).cross(pc - pa).normalized();
    for (int y = y_lo; y <= y_hi; ++y)
      for (int x = x_lo; x <= x_hi; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double l1 = ((c.x() - px) * (a.y() - py) - (c.y() - py) * (a.x() - px)) / area;
        const double l2 = ((a.x() - px) * (b.y() - py) - (a.y() - py) * (b.x() - px)) / area;
        const double l0 = 1 - l1 - l2;
        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
        const double z = l0 * a.z() + l1 * b.z() + l2 * c.z();
        double& stored = depth[static_cast<size_t>(y) * w + x];
        if (z >= stored) continue;
        stored = z;
        Eigen::Vector3d n = item.smooth ? Eigen::Vector3d(l0 * normals.row(i0) + l1 * normals.row(i1) + l2 * normals.row(i2))
                                        : face_normal;
        if (n.squaredNorm() > 0) n.normalize();
        if (n.dot(view.forward) > 0) n = -n;  // a back face seen through a gap: light it as front
        Eigen::Vector3d base(0.8, 0.8, 0.82);
        if (item.checker_coords) {
          const Eigen::Vector3d q = l0 * item.checker_coords->row(i0) + l1 * item.checker_coords->row(i1) +
                                    l2 * item.checker_coords->row(i2);
          base = checker_colour(q, item.checker_size);
        } else if (item.face_rgb) {
          base = item.face_rgb->row(f);
        }
        const double shade = 0.22 + 0.68 * std::max(0.0, n.dot(light)) + 0.18 * std::max(0.0, n.dot(fill));
        colour[static_cast<size_t>(y) * w + x] = (base * std::min(shade, 1.0)).cast<float>();
      }
  }
}

}  // namespace

Image render_tiles(const std::vector<RenderItem>& items, const RenderOptions& options) {
  if (items.empty()) throw AlgorithmError("render_tiles: nothing to render");
  if (options.tile_width < 1 || options.tile_height < 1 || options.supersampling < 1)
    throw AlgorithmError("render_tiles: tile size and supersampling must be positive");
  const int s = options.supersampling;
  const int w = options.tile_width * s, h = options.tile_height * s;
  Image image;
  image.width = options.tile_width * static_cast<int>(items.size());
  image.height = options.tile_height;
  image.channels = 3;
  image.pixels.assign(static_cast<size_t>(image.width) * image.height * 3, 0.0f);
  double max_scale = 0;  // the smallest of the items' own scales, when they share one
  if (options.same_scale) {
    max_scale = std::numeric_limits<double>::infinity();
    for (const RenderItem& item : items)
      if (item.mesh && item.mesh->num_faces() > 0) max_scale = std::min(max_scale, frame(item, options, w, h).scale);
  }
  for (size_t t = 0; t < items.size(); ++t) {
    const RenderItem& item = items[t];
    if (!item.mesh || item.mesh->num_faces() == 0) throw AlgorithmError("render_tiles: item without faces");
    if (item.checker_coords && item.checker_coords->rows() != item.mesh->num_vertices())
      throw AlgorithmError("render_tiles: checker_coords needs one row per vertex");
    if (item.face_rgb && item.face_rgb->rows() != item.mesh->num_faces())
      throw AlgorithmError("render_tiles: face_rgb needs one row per face");
    std::vector<Eigen::Vector3f> samples(static_cast<size_t>(w) * h, options.background.cast<float>());
    rasterise(item, options, w, h, max_scale, samples);
    // Box-filter the samples down to pixels.
    for (int y = 0; y < options.tile_height; ++y)
      for (int x = 0; x < options.tile_width; ++x) {
        Eigen::Vector3f sum = Eigen::Vector3f::Zero();
        for (int dy = 0; dy < s; ++dy)
          for (int dx = 0; dx < s; ++dx) sum += samples[static_cast<size_t>(y * s + dy) * w + (x * s + dx)];
        sum /= static_cast<float>(s * s);
        for (int c = 0; c < 3; ++c) image.at(static_cast<int>(t) * options.tile_width + x, y, c) = sum[c];
      }
  }
  return image;
}

Eigen::Vector3d distinct_colour(int index) {
  const double hue = std::fmod(index * 0.6180339887498949, 1.0) * 6.0;
  const double s = 0.55, v = 0.95;
  const int sector = static_cast<int>(hue) % 6;
  const double f = hue - std::floor(hue);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (sector) {
    case 0: return {v, t, p};
    case 1: return {q, v, p};
    case 2: return {p, v, t};
    case 3: return {p, q, v};
    case 4: return {t, p, v};
    default: return {v, p, q};
  }
}

}  // namespace polycube
