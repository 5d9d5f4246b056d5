#include "millsim/io/vtk_output.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <iterator>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

#include "millsim/core/constants.hpp"
#include "millsim/io/partial_file.hpp"

namespace millsim {
namespace {

using Buffer = fmt::memory_buffer;

/// A point in 3D: a 2D world's points lie in the plane z = 0.
template <int D>
std::array<double, 3> in_space(const Vec<D>& v) {
  if constexpr (D == 2) {
    return {v[0], v[1], 0.0};
  } else {
    return {v[0], v[1], v[2]};
  }
}

/// A spin as a vector: a 2D world's spins are about +z.
template <int D>
std::array<double, 3> spin_in_space(const Spin<D>& w) {
  if constexpr (D == 2) {
    return {0.0, 0.0, w};
  } else {
    return {w[0], w[1], w[2]};
  }
}

void open_array(Buffer& out, std::string_view type, std::string_view name, int components) {
  fmt::format_to(std::back_inserter(out), "        <DataArray type=\"{}\"", type);
  if (!name.empty()) fmt::format_to(std::back_inserter(out), " Name=\"{}\"", name);
  fmt::format_to(std::back_inserter(out), " NumberOfComponents=\"{}\" format=\"ascii\">\n",
                 components);
}

void close_array(Buffer& out) {
  fmt::format_to(std::back_inserter(out), "\n        </DataArray>\n");
}

/// A data array of triples, one a line.
void write_vectors(Buffer& out, std::string_view name,
                   const std::vector<std::array<double, 3>>& values) {
  open_array(out, "Float64", name, 3);
  for (std::size_t k = 0; k < values.size(); ++k) {
    fmt::format_to(std::back_inserter(out), "{}{} {} {}", k == 0 ? "" : "\n", values[k][0],
                   values[k][1], values[k][2]);
  }
  close_array(out);
}

template <typename T>
void write_values(Buffer& out, std::string_view type, std::string_view name,
                  const std::vector<T>& values) {
  open_array(out, type, name, 1);
  for (std::size_t k = 0; k < values.size(); ++k) {
    fmt::format_to(std::back_inserter(out), "{}{}", k == 0 ? "" : (k % 10 == 0 ? "\n" : " "),
                   values[k]);
  }
  close_array(out);
}

/// Cells of one kind (Verts, Lines or Polys): each a list of point indices.
void write_cells(Buffer& out, std::string_view kind,
                 const std::vector<std::vector<std::int64_t>>& cells) {
  fmt::format_to(std::back_inserter(out), "      <{}>\n", kind);
  std::vector<std::int64_t> connectivity;
  std::vector<std::int64_t> offsets;
  for (const auto& cell : cells) {
    connectivity.insert(connectivity.end(), cell.begin(), cell.end());
    offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
  }
  write_values(out, "Int64", "connectivity", connectivity);
  write_values(out, "Int64", "offsets", offsets);
  fmt::format_to(std::back_inserter(out), "      </{}>\n", kind);
}

constexpr std::string_view file_head =
    "<?xml version=\"1.0\"?>\n"
    "<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\" "
    "header_type=\"UInt64\">\n"
    "  <PolyData>\n";
constexpr std::string_view file_tail =
    "    </Piece>\n"
    "  </PolyData>\n"
    "</VTKFile>\n";

/// A polygon mesh being built: its points, and its cells by kind with the wall each belongs to.
struct Mesh {
  std::vector<std::array<double, 3>> points;
  std::vector<std::vector<std::int64_t>> lines;
  std::vector<std::int64_t> line_wall;
  std::vector<std::vector<std::int64_t>> polys;
  std::vector<std::int64_t> poly_wall;

  std::int64_t add(const std::array<double, 3>& p) {
    points.push_back(p);
    return static_cast<std::int64_t>(points.size()) - 1;
  }
  void add_poly(std::vector<std::int64_t> corners, std::int64_t wall) {
    polys.push_back(std::move(corners));
    poly_wall.push_back(wall);
  }
};

constexpr std::int64_t shell_wall = 0;
constexpr std::int64_t lifter_wall = 1;
constexpr std::int64_t end_wall = 2;

/// The point at `radius` and `angle` about the axis, at `z`.
std::array<double, 3> on_circle(double radius, double angle, double z) {
  return {radius * std::cos(angle), radius * std::sin(angle), z};
}

/// A ring of points at `radius` and `z`, turned with the shell; the index of its first.
std::int64_t add_ring(Mesh& mesh, double radius, double z, double shell_angle) {
  const std::int64_t first = static_cast<std::int64_t>(mesh.points.size());
  for (int k = 0; k < shell_segments; ++k) {
    mesh.add(on_circle(radius, shell_angle + 2.0 * pi * k / shell_segments, z));
  }
  return first;
}

// Polygons are wound so that their normals (right-handed) point out of the closed surface
// they belong to: out of the mill (the shell radially out, the near end towards −z, the far
// end towards +z) and out of each lifter's box, into the mill.

/// Quadrilaterals joining two rings of add_ring: facing radially out when `b` lies further
/// along +z than `a`.
void join_rings(Mesh& mesh, std::int64_t a, std::int64_t b, std::int64_t wall) {
  for (std::int64_t k = 0; k < shell_segments; ++k) {
    const std::int64_t next = (k + 1) % shell_segments;
    mesh.add_poly({a + k, a + next, b + next, b + k}, wall);
  }
}

/// The disc closing a ring of add_ring, facing +z (`towards_plus_z`) or −z.
void close_ring(Mesh& mesh, std::int64_t ring, bool towards_plus_z) {
  std::vector<std::int64_t> corners;
  for (std::int64_t k = 0; k < shell_segments; ++k) corners.push_back(ring + k);
  if (!towards_plus_z) std::reverse(corners.begin(), corners.end());
  mesh.add_poly(std::move(corners), end_wall);
}

/// Lifter k's corner at radial a and tangential b (its own frame, mill_geometry.cpp), at z.
std::array<double, 3> lifter_corner(const Mill2D& mill, std::size_t k, double a, double b,
                                    double z) {
  const Vec2 radial = mill.lifter_direction[k];
  return {a * radial[0] - b * radial[1], a * radial[1] + b * radial[0], z};
}

Mesh mill_mesh(const Mill2D& mill) {
  Mesh mesh;
  const std::int64_t ring = add_ring(mesh, mill.radius, 0.0, mill.angle);
  std::vector<std::int64_t> line;
  for (std::int64_t k = 0; k <= shell_segments; ++k) line.push_back(ring + k % shell_segments);
  mesh.lines.push_back(std::move(line));
  mesh.line_wall.push_back(shell_wall);
  // The part of a bar inside the shell (its frame spans a ∈ [R − h, R + h]; beyond R it only
  // closes the shape).
  const double inner = mill.radius - mill.lifter_height;
  const double half = 0.5 * mill.lifter_width;
  for (std::size_t k = 0; k < mill.lifter_direction.size(); ++k) {
    std::vector<std::int64_t> corners;
    for (const auto& [a, b] : {std::pair{inner, -half}, std::pair{mill.radius, -half},
                               std::pair{mill.radius, half}, std::pair{inner, half}}) {
      corners.push_back(mesh.add(lifter_corner(mill, k, a, b, 0.0)));
    }
    mesh.add_poly(std::move(corners), lifter_wall);
  }
  return mesh;
}

Mesh mill_mesh(const Mill3D& mill) {
  Mesh mesh;
  const double length = mill.length;
  const std::int64_t near = add_ring(mesh, mill.radius, 0.0, mill.angle);
  const std::int64_t far = add_ring(mesh, mill.radius, length, mill.angle);
  join_rings(mesh, near, far, shell_wall);
  const double inner = mill.radius - mill.lifter_height;
  const double half = 0.5 * mill.lifter_width;
  for (std::size_t k = 0; k < mill.lifter_direction.size(); ++k) {
    // Corners 0-3 at z = 0, 4-7 at the far end, each end's in the order of the 2D rectangle.
    std::array<std::int64_t, 8> c{};
    int n = 0;
    for (const double z : {0.0, length}) {
      for (const auto& [a, b] : {std::pair{inner, -half}, std::pair{mill.radius, -half},
                                 std::pair{mill.radius, half}, std::pair{inner, half}}) {
        c[static_cast<std::size_t>(n++)] = mesh.add(lifter_corner(mill, k, a, b, z));
      }
    }
    const auto face = [&](int p, int q, int r, int s) {
      mesh.add_poly({c[static_cast<std::size_t>(p)], c[static_cast<std::size_t>(q)],
                     c[static_cast<std::size_t>(r)], c[static_cast<std::size_t>(s)]},
                    lifter_wall);
    };
    face(3, 2, 1, 0);  // the ends: at z = 0 facing −z, at the far end +z
    face(4, 5, 6, 7);
    face(0, 1, 5, 4);  // the sides
    face(1, 2, 6, 5);
    face(2, 3, 7, 6);
    face(3, 0, 4, 7);
  }
  if (mill.periodic) return mesh;
  if (!mill.has_cones()) {
    close_ring(mesh, near, false);
    close_ring(mesh, far, true);
    return mesh;
  }
  const double trunnion = mill.trunnion_radius();
  const double c = mill.cone_length;
  const std::int64_t near_trunnion = add_ring(mesh, trunnion, -c, mill.angle);
  const std::int64_t far_trunnion = add_ring(mesh, trunnion, length + c, mill.angle);
  join_rings(mesh, near_trunnion, near, end_wall);  // from the trunnion towards +z: outward
  join_rings(mesh, far, far_trunnion, end_wall);
  close_ring(mesh, near_trunnion, false);
  close_ring(mesh, far_trunnion, true);
  return mesh;
}

}  // namespace

template <int D>
std::string particles_vtp(const World<D>& world) {
  const ParticleStore<D>& p = world.particles();
  const std::size_t n = p.size();
  std::vector<std::array<double, 3>> position(n), velocity(n), spin(n), force(n);
  std::vector<double> radius(n);
  std::vector<std::int64_t> id(n);
  std::vector<std::vector<std::int64_t>> vertices(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = world.particle_index(k);
    const auto [v, w] = motion_at_positions(world, i);
    position[k] = in_space<D>(p.position[i]);
    velocity[k] = in_space<D>(v);
    spin[k] = spin_in_space<D>(w);
    force[k] = in_space<D>(p.force[i]);
    radius[k] = p.radius[i];
    id[k] = static_cast<std::int64_t>(k);
    vertices[k] = {static_cast<std::int64_t>(k)};
  }
  Buffer out;
  out.append(file_head);
  fmt::format_to(std::back_inserter(out),
                 "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"{}\" NumberOfLines=\"0\" "
                 "NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n",
                 n, n);
  out.append(std::string_view("      <PointData Scalars=\"radius\" Vectors=\"velocity\">\n"));
  write_values(out, "Int64", "id", id);
  write_values(out, "Float64", "radius", radius);
  write_vectors(out, "velocity", velocity);
  write_vectors(out, "angular_velocity", spin);
  write_vectors(out, "force", force);
  out.append(std::string_view("      </PointData>\n      <Points>\n"));
  write_vectors(out, "", position);
  out.append(std::string_view("      </Points>\n"));
  write_cells(out, "Verts", vertices);
  out.append(file_tail);
  return fmt::to_string(out);
}

template <int D>
std::string mill_vtp(const World<D>& world) {
  const Mesh mesh = world.walls().mill ? mill_mesh(*world.walls().mill) : Mesh{};
  Buffer out;
  out.append(file_head);
  fmt::format_to(std::back_inserter(out),
                 "    <Piece NumberOfPoints=\"{}\" NumberOfVerts=\"0\" NumberOfLines=\"{}\" "
                 "NumberOfStrips=\"0\" NumberOfPolys=\"{}\">\n",
                 mesh.points.size(), mesh.lines.size(), mesh.polys.size());
  // VTK orders a PolyData file's cells verts, lines, strips, polys: so does the cell array.
  std::vector<std::int64_t> wall = mesh.line_wall;
  wall.insert(wall.end(), mesh.poly_wall.begin(), mesh.poly_wall.end());
  out.append(std::string_view("      <CellData Scalars=\"wall\">\n"));
  write_values(out, "Int64", "wall", wall);
  out.append(std::string_view("      </CellData>\n      <Points>\n"));
  write_vectors(out, "", mesh.points);
  out.append(std::string_view("      </Points>\n"));
  write_cells(out, "Lines", mesh.lines);
  write_cells(out, "Polys", mesh.polys);
  out.append(file_tail);
  return fmt::to_string(out);
}

template std::string particles_vtp(const World<2>&);
template std::string particles_vtp(const World<3>&);
template std::string mill_vtp(const World<2>&);
template std::string mill_vtp(const World<3>&);

namespace {

constexpr std::string_view collection_head =
    "<?xml version=\"1.0\"?>\n"
    "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
    "  <Collection>\n";
constexpr std::string_view collection_tail =
    "  </Collection>\n"
    "</VTKFile>\n";

}  // namespace

PvdCollection::PvdCollection(std::filesystem::path path) : path_(std::move(path)) {}

PvdCollection::~PvdCollection() {
  if (file_ != nullptr) std::fclose(file_);
}

void PvdCollection::add(double time, const std::vector<std::string>& files) {
  const bool first = file_ == nullptr;
  if (first) {
    file_ = std::fopen(path_.c_str(), "wb");
    if (file_ == nullptr) {
      throw std::runtime_error(
          fmt::format("{}: cannot write: {}", path_.string(), std::strerror(errno)));
    }
    // Unbuffered: each add is one write, and nothing of a failed one stays pending.
    std::setvbuf(file_, nullptr, _IONBF, 0);
  }
  Buffer text;
  if (first) text.append(collection_head);
  for (std::size_t part = 0; part < files.size(); ++part) {
    fmt::format_to(std::back_inserter(text),
                   "    <DataSet timestep=\"{}\" group=\"\" part=\"{}\" file=\"{}\"/>\n", time,
                   part, files[part]);
  }
  const auto entries_size = static_cast<long>(text.size());
  text.append(collection_tail);
  // The new entries over the old closing tags, then the closing tags again: the file only
  // grows, and is whole again once this returns.
  errno = 0;
  if (std::fseek(file_, entries_end_, SEEK_SET) == 0 &&
      std::fwrite(text.data(), 1, text.size(), file_) == text.size() && std::fflush(file_) == 0) {
    entries_end_ += entries_size;
    return;
  }
  // Failed (a full disk, say): the collection as it was, whole, with what it listed (the
  // first add's file removed: it listed nothing).
  undo_failed_append(file_, path_, entries_end_, first, errno, collection_tail);
}

}  // namespace millsim
