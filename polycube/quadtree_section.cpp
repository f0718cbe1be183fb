#include "polycube/quadtree_section.h"

#include "polycube/quadtree_topology.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace polycube {

namespace {

using Vec2 = Eigen::Vector2d;

constexpr double kUnit = 1.0 / kQuadGridSize;

// A contour crossing a cell, clipped to it.
struct Clip {
  int contour = -1;  // local index
  std::vector<Vec2> polygon;
  double area = 0;  // absolute area of the clipped polygon
};

struct Node {
  QuadCell cell;
  int first_child = -1;  // children at first_child .. first_child + 3
  bool imposed = false;  // its face comes from a label edit
  int base_face = 0;     // face just inside the deepest contour around the whole cell
  int accuracy_level = 0;  // level of the d_a refinement's leaf containing it
  std::vector<Clip> clips;
  int face = 0;
  std::vector<std::pair<int, double>> face_areas;
};

double polygon_area(const std::vector<Vec2>& polygon) {
  double twice = 0;
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2& p = polygon[i];
    const Vec2& q = polygon[(i + 1) % n];
    twice += p.x() * q.y() - q.x() * p.y();
  }
  return 0.5 * twice;
}

// Sutherland–Hodgman against the half-plane sign * (p[axis] - c) >= 0. Points created on the
// line get exactly c, so later tests against the line are exact.
void clip_half_plane(const std::vector<Vec2>& in, int axis, double c, int sign, std::vector<Vec2>& out) {
  out.clear();
  const size_t n = in.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2& p = in[i];
    const Vec2& q = in[(i + 1) % n];
    const bool p_in = sign * (p[axis] - c) >= 0, q_in = sign * (q[axis] - c) >= 0;
    if (p_in) out.push_back(p);
    if (p_in != q_in) {
      const double t = (c - p[axis]) / (q[axis] - p[axis]);
      Vec2 r = p + t * (q - p);
      r[axis] = c;
      const int other = 1 - axis;
      r[other] = std::clamp(r[other], std::min(p[other], q[other]), std::max(p[other], q[other]));
      out.push_back(r);
    }
  }
}

struct Box {
  double x0, y0, x1, y1;
  explicit Box(const QuadCell& c)
      : x0(c.x0() * kUnit), y0(c.y0() * kUnit), x1(c.x1() * kUnit), y1(c.y1() * kUnit) {}
  double area() const { return (x1 - x0) * (y1 - y0); }
  bool strictly_inside(const Vec2& p) const { return p.x() > x0 && p.x() < x1 && p.y() > y0 && p.y() < y1; }
};

class Builder {
 public:
  Builder(const CrossSections& sections, int plane) : sections_(sections), section_(sections.planes[plane]) {
    Node root;
    const int k = static_cast<int>(section_.contours.size());
    for (int i = 0; i < k; ++i) {
      Clip clip;
      clip.contour = i;
      clip.polygon = contour(i).points;
      root.clips.push_back(std::move(clip));
    }
    nodes_.push_back(std::move(root));
    // The root's clips are the whole contours: classify them against the unit square like any
    // child (a contour entirely inside it is "crossing" as it has vertices inside).
    std::vector<Clip> all = std::move(nodes_[0].clips);
    nodes_[0].clips.clear();
    classify(0, all, 0);
  }

  // Subdivides a leaf into four children.
  void split(int n) {
    const int first = static_cast<int>(nodes_.size());
    const QuadCell parent_cell = nodes_[n].cell;
    std::vector<Clip> clips = std::move(nodes_[n].clips);
    const int base = nodes_[n].base_face;
    nodes_[n].clips.clear();
    nodes_[n].clips.shrink_to_fit();
    nodes_[n].face_areas.clear();
    nodes_[n].first_child = first;
    const int accuracy_level = refining_accuracy_ ? parent_cell.level + 1 : nodes_[n].accuracy_level;
    for (int q = 0; q < 4; ++q) {
      Node child;
      child.cell = {parent_cell.level + 1, 2 * parent_cell.ix + (q & 1), 2 * parent_cell.iy + (q >> 1)};
      child.accuracy_level = accuracy_level;
      nodes_.push_back(std::move(child));
      classify(first + q, clips, base);
    }
    deepest_ = std::max(deepest_, parent_cell.level + 1);
  }

  // Imposes the faces of label edits on the current leaves and on every leaf made later.
  void impose(const std::vector<std::pair<QuadCell, int>>& labels) {
    for (const auto& [cell, face] : labels)
      if (face >= 0 && face < section_.num_faces()) labels_[cell] = face;
    for (Node& node : nodes_) {
      if (node.first_child >= 0) continue;
      const int f = imposed_face(node.cell);
      if (f < 0) continue;
      node.face = f;
      node.imposed = true;
    }
  }

  std::vector<int> leaves() const {
    std::vector<int> result;
    for (int n = 0; n < static_cast<int>(nodes_.size()); ++n)
      if (nodes_[n].first_child < 0) result.push_back(n);
    return result;
  }
  const Node& node(int n) const { return nodes_[n]; }
  int size() const { return static_cast<int>(nodes_.size()); }
  int deepest() const { return deepest_; }
  // Splits from now on are not for d_a: their leaves keep the level of the leaf they refine.
  void accuracy_done() { refining_accuracy_ = false; }

  // Subdivides the leaves containing `cell` down to below its level.
  int split_down_to(const QuadCell& cell) {
    int splits = 0, n = 0;
    while (true) {
      const QuadCell c = nodes_[n].cell;
      if (c.level > cell.level) break;
      if (nodes_[n].first_child < 0) {
        split(n);
        ++splits;
      }
      if (c.level == cell.level) break;
      const int shift = cell.level - c.level - 1;
      const int qx = (cell.ix >> shift) & 1, qy = (cell.iy >> shift) & 1;
      n = nodes_[n].first_child + qx + 2 * qy;
    }
    return splits;
  }

 private:
  const SectionContour& contour(int local) const { return sections_.contours[section_.contours[local]]; }

  // Clips the parent's crossing contours to node n, sets its base face, face areas and label.
  void classify(int n, const std::vector<Clip>& parent_clips, int parent_base) {
    Node& node = nodes_[n];
    const Box box(node.cell);
    int deepest_containing = -1;
    std::vector<Vec2> a, b;
    for (const Clip& parent : parent_clips) {
      clip_half_plane(parent.polygon, 0, box.x0, +1, a);
      clip_half_plane(a, 0, box.x1, -1, b);
      clip_half_plane(b, 1, box.y0, +1, a);
      clip_half_plane(a, 1, box.y1, -1, b);
      bool crossing = false;
      for (size_t i = 0; i < b.size() && !crossing; ++i)
        crossing = box.strictly_inside(b[i]) || box.strictly_inside(0.5 * (b[i] + b[(i + 1) % b.size()]));
      const double area = std::abs(polygon_area(b));
      if (crossing) {
        Clip clip;
        clip.contour = parent.contour;
        clip.polygon = b;
        clip.area = area;
        node.clips.push_back(std::move(clip));
      } else if (area > 0.5 * box.area()) {
        if (deepest_containing < 0 || contour(parent.contour).depth > contour(deepest_containing).depth)
          deepest_containing = parent.contour;
      }
    }
    node.base_face = deepest_containing >= 0 ? deepest_containing + 1 : parent_base;
    node.face_areas.clear();
    const int imposed = imposed_face(node.cell);
    node.imposed = imposed >= 0;
    if (node.clips.empty()) {
      node.face = imposed >= 0 ? imposed : node.base_face;
      return;
    }
    auto add = [&](int face, double area) {
      for (auto& [f, value] : node.face_areas)
        if (f == face) {
          value += area;
          return;
        }
      node.face_areas.emplace_back(face, area);
    };
    add(node.base_face, box.area());
    for (const Clip& clip : node.clips) {
      const int face = clip.contour + 1;
      add(face, clip.area);
      add(section_.face_parent[face], -clip.area);
    }
    node.face_areas.erase(std::remove_if(node.face_areas.begin(), node.face_areas.end(),
                                         [](const std::pair<int, double>& fa) { return !(fa.second > 0); }),
                          node.face_areas.end());
    std::sort(node.face_areas.begin(), node.face_areas.end());
    node.face = node.base_face;
    double best = -1;
    for (const auto& [f, value] : node.face_areas)
      if (value > best) {
        best = value;
        node.face = f;
      }
    if (imposed >= 0) node.face = imposed;
  }

  // The face a label edit imposes on a cell (through it or an ancestor), -1 if none.
  int imposed_face(const QuadCell& cell) const {
    if (labels_.empty()) return -1;
    for (int l = cell.level; l >= 0; --l) {
      const QuadCell ancestor{l, cell.ix >> (cell.level - l), cell.iy >> (cell.level - l)};
      const auto it = labels_.find(ancestor);
      if (it != labels_.end()) return it->second;
    }
    return -1;
  }

  const CrossSections& sections_;
  const PlaneSection& section_;
  std::map<QuadCell, int> labels_;
  std::vector<Node> nodes_;
  int deepest_ = 0;
  bool refining_accuracy_ = true;
};

QuadLeaf leaf_of(const Node& node) {
  QuadLeaf leaf;
  leaf.cell = node.cell;
  leaf.face = node.face;
  leaf.mixed = !node.clips.empty();
  if (leaf.mixed) leaf.face_areas = node.face_areas;
  leaf.accuracy_level = node.accuracy_level;
  return leaf;
}

// Per solid face: area of the symmetric difference between its cells and its true area.
std::vector<double> symmetric_difference(const PlaneSection& section, const Builder& builder,
                                         const std::vector<int>& leaves) {
  std::vector<double> error(section.num_faces(), 0.0);
  for (int n : leaves) {
    const Node& node = builder.node(n);
    if (node.clips.empty()) continue;
    const double box = Box(node.cell).area();
    double own = 0;
    for (const auto& [f, a] : node.face_areas) {
      if (f == node.face) own = a;
      else if (section.face_solid[f]) error[f] += a;
    }
    if (section.face_solid[node.face]) error[node.face] += std::max(0.0, box - own);
  }
  return error;
}

}  // namespace

QuadtreeSection approximate_section(const CrossSections& sections, int plane, const QuadtreeEdits& edits,
                                    const QuadtreeOptions& options) {
  const PlaneSection& section = sections.planes[plane];
  Builder builder(sections, plane);
  QuadtreeSection result;
  const int nf = section.num_faces();
  const int max_level = std::min(options.max_level, kQuadGridBits);
  const int max_repair_level = std::min(std::max(options.max_repair_level, max_level), kQuadGridBits);

  // §3.2: subdivide until every region is within d_a, refining each failing region's coarsest
  // boundary cells first (uniform boundary resolution per region).
  while (true) {
    const std::vector<int> leaves = builder.leaves();
    const std::vector<double> error = symmetric_difference(section, builder, leaves);
    // Per failing region, the coarsest level of its boundary cells that may still be split.
    constexpr int kNone = -1, kFailing = 1 << 30;
    std::vector<int> level(nf, kNone);
    for (int f = 1; f < nf; ++f)
      if (section.face_solid[f] && error[f] > options.da * section.face_area[f]) level[f] = kFailing;
    for (int n : leaves) {
      const Node& node = builder.node(n);
      if (node.cell.level >= max_level || node.imposed) continue;
      for (const auto& [f, a] : node.face_areas)
        if (level[f] != kNone) level[f] = std::min(level[f], node.cell.level);
    }
    std::vector<int> to_split;
    for (int n : leaves) {
      const Node& node = builder.node(n);
      if (node.cell.level >= max_level || node.imposed) continue;
      for (const auto& [f, a] : node.face_areas)
        if (level[f] == node.cell.level) {
          to_split.push_back(n);
          break;
        }
    }
    if (options.feature_distance > 0) {
      std::vector<char> split(builder.size(), 0);
      for (int n : to_split) split[n] = 1;
      std::vector<std::vector<int>> labelled(nf);
      for (int n : leaves) labelled[builder.node(n).face].push_back(n);
      for (int n : leaves) {
        const Node& node = builder.node(n);
        if (split[n] || node.clips.empty() || node.cell.level >= max_level || node.imposed) continue;
        const Box box(node.cell);
        const double side = box.x1 - box.x0;
        if (side <= options.feature_distance) continue;
        for (const auto& [f, a] : node.face_areas) {
          if (f == node.face || !section.face_solid[f] || a <= 0.05 * box.area()) continue;
          bool touches = false;
          for (int m : labelled[f]) {
            const Box other(builder.node(m).cell);
            if (other.x0 <= box.x1 && box.x0 <= other.x1 && other.y0 <= box.y1 && box.y0 <= other.y1) {
              touches = true;
              break;
            }
          }
          if (!touches || side > 4 * options.feature_distance) {
            to_split.push_back(n);
            ++result.feature_splits;
            break;
          }
        }
      }
    }
    if (to_split.empty()) break;
    for (int n : to_split) builder.split(n);
    result.accuracy_splits += static_cast<int>(to_split.size());
  }

  builder.accuracy_done();
  for (const QuadCell& cell : edits.splits)
    if (cell.level < max_repair_level) result.forced_splits += builder.split_down_to(cell);

  // Topology: subdivide where the labelling violates a condition, until none is left. Then the
  // label edits, which are accepted only if the conditions still hold (after a few more
  // subdivisions of cells they do not fix).
  std::vector<QuadLeaf> leaves;
  std::vector<int> leaf_nodes;
  const size_t leaf_budget = std::max<size_t>(builder.leaves().size(), options.max_leaves);
  bool labelled = edits.labels.empty();
  for (int round = 0, rounds_after_labels = 0, relabel_rounds = 0;; ++round) {
    leaf_nodes = builder.leaves();
    leaves.clear();
    for (int n : leaf_nodes) leaves.push_back(leaf_of(builder.node(n)));
    std::vector<char> mark;
    const std::string problem = check_section_topology(section, leaves, mark);
    if (problem.empty() && labelled) {
      result.valid = true;
      break;
    }
    if (problem.empty()) {
      // A relabelled cell must be a leaf or subdivided: split its ancestors.
      for (const auto& [cell, face] : edits.labels)
        if (cell.level > 0) result.forced_splits += builder.split_down_to({cell.level - 1, cell.ix >> 1, cell.iy >> 1});
      builder.impose(edits.labels);
      labelled = true;
      continue;
    }
    std::vector<int> to_split;
    for (size_t l = 0; l < leaves.size(); ++l)
      if (mark[l] && leaves[l].mixed && !builder.node(leaf_nodes[l]).imposed && leaves[l].cell.level < max_repair_level)
        to_split.push_back(leaf_nodes[l]);
    if (labelled && !edits.labels.empty()) ++rounds_after_labels;
    const bool stalled = to_split.empty() || round >= options.max_repair_rounds || rounds_after_labels > 4 ||
                         leaves.size() + 3 * to_split.size() > leaf_budget;
    if (stalled && relabel_rounds < 8 && edits.labels.empty()) {
      // Subdivision cannot help (slivers or gaps finer than the deepest cells): relabel locally.
      // Not with label edits: those are trials of the stacking repairs, to be rejected quickly.
      const std::vector<std::pair<int, int>> relabels = section_topology_relabels(section, leaves);
      if (!relabels.empty()) {
        std::vector<std::pair<QuadCell, int>> cells;
        for (const auto& [l, f] : relabels) cells.emplace_back(leaves[l].cell, f);
        builder.impose(cells);
        result.topology_relabels += static_cast<int>(cells.size());
        ++relabel_rounds;
        continue;
      }
    }
    if (stalled) {
      std::ostringstream message;
      message << "plane " << plane << " (z = " << section.z << "): " << problem << " after " << round
              << " repair rounds (level limit " << max_repair_level << ", " << leaves.size() << " cells)";
      result.problem = message.str();
      break;
    }
    for (int n : to_split) builder.split(n);
    result.topology_splits += static_cast<int>(to_split.size());
  }

  result.leaves = std::move(leaves);
  result.deepest_level = builder.deepest();
  result.region_error = symmetric_difference(section, builder, leaf_nodes);
  for (int f = 0; f < nf; ++f)
    result.region_error[f] = section.face_solid[f] && section.face_area[f] > 0 ? result.region_error[f] / section.face_area[f] : 0;
  return result;
}

}  // namespace polycube
