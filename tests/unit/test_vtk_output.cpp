// Snapshots for ParaView (io/vtk_output.hpp): the particles' file reads back to the World's
// values, the mill's walls lie where the contact geometry has them, and the collection is a
// whole file after every snapshot.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <csignal>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "millsim/builtin_example.hpp"
#include "millsim/core/constants.hpp"
#include "millsim/io/config.hpp"
#include "millsim/io/output.hpp"
#include "millsim/io/partial_file.hpp"
#include "millsim/io/vtk_output.hpp"
#include "millsim/sim/charge.hpp"
#include "support/program_test.hpp"
#include "support/temporary_directory.hpp"

namespace millsim {
namespace {

using testing::read_all;

/// The built-in example mill with `overrides`, placed and stepped `steps` times, its
/// particles renumbered into cell order at every rebuild (so that ids and indices differ).
template <int D>
World<D> example_world(std::vector<std::string> overrides, int steps) {
  overrides.push_back("output.snapshot_interval=0");
  const MillPlan plan =
      plan_mill(parse_mill_config(builtin_example_toml, "lab-mill-2d.toml", overrides));
  World<D> world = build_mill_world<D>(plan);
  world.set_cell_order_interval(1);
  for (int n = 0; n < steps; ++n) world.step();
  return world;
}

/// The numbers of the data array whose opening tag holds `attribute` (e.g. `Name="radius"`,
/// or `NumberOfComponents="3" format` for the points', which have no name); a test failure,
/// and none, if there is no such array.
std::vector<double> array_of(std::string_view file, std::string_view attribute) {
  std::size_t at = 0;
  while ((at = file.find("<DataArray", at)) != std::string_view::npos) {
    const std::size_t tag_end = file.find('>', at);
    const std::string_view tag = file.substr(at, tag_end - at);
    at = tag_end;
    if (tag.find(attribute) == std::string_view::npos) continue;
    if (attribute.find("Name") == std::string_view::npos &&
        tag.find("Name=") != std::string_view::npos) {
      continue;
    }
    const std::size_t end = file.find("</DataArray>", tag_end);
    std::istringstream numbers(std::string(file.substr(tag_end + 1, end - tag_end - 1)));
    std::vector<double> values;
    for (std::string word; numbers >> word;) values.push_back(std::stod(word));
    return values;
  }
  ADD_FAILURE() << "no data array with " << attribute;
  return {};
}

/// The value of `attribute` (e.g. NumberOfPolys) in the file's Piece tag.
long piece_count(std::string_view file, std::string_view attribute) {
  const std::size_t piece = file.find("<Piece");
  const std::size_t at = file.find(std::string(attribute) + "=\"", piece);
  if (piece == std::string_view::npos || at == std::string_view::npos) {
    ADD_FAILURE() << "no " << attribute;
    return -1;
  }
  return std::stol(std::string(file.substr(at + attribute.size() + 2)));
}

TEST(VtkOutput, ParticlesReadBackToTheWorldsValuesById) {
  const World<3> world = example_world<3>({"simulation.dimension=3"}, 300);
  const std::string file = particles_vtp(world);
  const std::size_t n = world.particles().size();
  ASSERT_GT(n, 100U);
  EXPECT_TRUE(file.starts_with("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\""));
  EXPECT_TRUE(file.ends_with("</Piece>\n  </PolyData>\n</VTKFile>\n"));
  EXPECT_EQ(piece_count(file, "NumberOfPoints"), static_cast<long>(n));
  EXPECT_EQ(piece_count(file, "NumberOfVerts"), static_cast<long>(n));
  const std::vector<double> id = array_of(file, "Name=\"id\"");
  const std::vector<double> radius = array_of(file, "Name=\"radius\"");
  const std::vector<double> velocity = array_of(file, "Name=\"velocity\"");
  const std::vector<double> spin = array_of(file, "Name=\"angular_velocity\"");
  const std::vector<double> force = array_of(file, "Name=\"force\"");
  const std::vector<double> points = array_of(file, "NumberOfComponents=\"3\" format");
  const std::vector<double> connectivity = array_of(file, "Name=\"connectivity\"");
  const std::vector<double> offsets = array_of(file, "Name=\"offsets\"");
  ASSERT_EQ(id.size(), n);
  ASSERT_EQ(radius.size(), n);
  ASSERT_EQ(velocity.size(), 3 * n);
  ASSERT_EQ(spin.size(), 3 * n);
  ASSERT_EQ(force.size(), 3 * n);
  ASSERT_EQ(points.size(), 3 * n);
  ASSERT_EQ(connectivity.size(), n);
  ASSERT_EQ(offsets.size(), n);
  const ParticleStore<3>& p = world.particles();
  std::size_t renumbered = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = world.particle_index(k);
    renumbered += i != k ? 1 : 0;
    const auto [v, w] = motion_at_positions(world, i);
    EXPECT_EQ(id[k], static_cast<double>(k));
    EXPECT_EQ(connectivity[k], static_cast<double>(k));
    EXPECT_EQ(offsets[k], static_cast<double>(k + 1));
    EXPECT_EQ(radius[k], p.radius[i]);
    for (int c = 0; c < 3; ++c) {
      const std::size_t at = 3 * k + static_cast<std::size_t>(c);
      EXPECT_EQ(points[at], p.position[i][c]) << "particle " << k;
      EXPECT_EQ(velocity[at], v[c]) << "particle " << k;
      EXPECT_EQ(spin[at], w[c]) << "particle " << k;
      EXPECT_EQ(force[at], p.force[i][c]) << "particle " << k;
    }
  }
  EXPECT_GT(renumbered, 0U) << "the test should see particles listed by id, not by index";
}

TEST(VtkOutput, TwoDimensionalParticlesLieInThePlaneAndSpinAboutZ) {
  const World<2> world = example_world<2>({}, 300);
  const std::string file = particles_vtp(world);
  const std::vector<double> points = array_of(file, "NumberOfComponents=\"3\" format");
  const std::vector<double> spin = array_of(file, "Name=\"angular_velocity\"");
  const std::size_t n = world.particles().size();
  ASSERT_EQ(points.size(), 3 * n);
  ASSERT_EQ(spin.size(), 3 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t i = world.particle_index(k);
    EXPECT_EQ(points[3 * k], world.particles().position[i][0]);
    EXPECT_EQ(points[3 * k + 1], world.particles().position[i][1]);
    EXPECT_EQ(points[3 * k + 2], 0.0);
    EXPECT_EQ(spin[3 * k], 0.0);
    EXPECT_EQ(spin[3 * k + 1], 0.0);
    EXPECT_EQ(spin[3 * k + 2], motion_at_positions(world, i).second);
  }
}

TEST(VtkOutput, TwoDimensionalMillIsTheShellCircleAndTheLifterRectangles) {
  // The built-in example: R = 0.45 m, 8 lifters 0.04 m high and wide; turned to 0.3 rad.
  World<2> world = example_world<2>({}, 0);
  world.walls().mill->turn_to(0.3);
  const std::string file = mill_vtp(world);
  const Mill2D& mill = *world.walls().mill;
  ASSERT_EQ(mill.lifter_count, 8);
  EXPECT_EQ(piece_count(file, "NumberOfLines"), 1);
  EXPECT_EQ(piece_count(file, "NumberOfPolys"), 8);
  const std::vector<double> points = array_of(file, "NumberOfComponents=\"3\" format");
  ASSERT_EQ(points.size(), 3U * (shell_segments + 4 * 8));
  for (int k = 0; k < shell_segments; ++k) {
    const double* p = &points[3 * static_cast<std::size_t>(k)];
    EXPECT_NEAR(std::hypot(p[0], p[1]), 0.45, 1e-15);
    EXPECT_EQ(p[2], 0.0);
  }
  // Lifter j's corners: radial a = R − h or R, tangential b = ∓w/2, about the direction
  // 0.3 + 2πj/8 (lifter 0 sits at the shell's angle).
  for (int j = 0; j < 8; ++j) {
    const double angle = 0.3 + 2.0 * pi * j / 8.0;
    const double expected[4][2] = {{0.41, -0.02}, {0.45, -0.02}, {0.45, 0.02}, {0.41, 0.02}};
    for (int c = 0; c < 4; ++c) {
      const double* p = &points[3 * static_cast<std::size_t>(shell_segments + 4 * j + c)];
      const double a = p[0] * std::cos(angle) + p[1] * std::sin(angle);
      const double b = -p[0] * std::sin(angle) + p[1] * std::cos(angle);
      EXPECT_NEAR(a, expected[c][0], 1e-15) << "lifter " << j << " corner " << c;
      EXPECT_NEAR(b, expected[c][1], 1e-15) << "lifter " << j << " corner " << c;
    }
  }
  // The wall of each cell: the shell's line, then the lifters.
  const std::vector<double> wall = array_of(file, "Name=\"wall\"");
  ASSERT_EQ(wall.size(), 9U);
  EXPECT_EQ(wall[0], 0.0);
  EXPECT_TRUE(std::all_of(wall.begin() + 1, wall.end(), [](double w) { return w == 1.0; }));
  const std::vector<double> line = array_of(file, "Name=\"connectivity\"");
  ASSERT_GE(line.size(), static_cast<std::size_t>(shell_segments + 1));
  EXPECT_EQ(line[0], 0.0);
  EXPECT_EQ(line[shell_segments], 0.0) << "the shell's line closes on its first point";
}

TEST(VtkOutput, ThreeDimensionalMillsHaveTheirEndsOrNone) {
  const auto polys_of = [](const World<3>& world) {
    return piece_count(mill_vtp(world), "NumberOfPolys");
  };
  // Flat ends: the shell's quadrilaterals, six faces a lifter, two end plates.
  const World<3> flat = example_world<3>({"simulation.dimension=3"}, 0);
  EXPECT_EQ(polys_of(flat), shell_segments + 6 * 8 + 2);
  const std::string flat_file = mill_vtp(flat);
  const std::vector<double> points = array_of(flat_file, "NumberOfComponents=\"3\" format");
  ASSERT_GE(points.size(), 3U * 2 * shell_segments);
  for (int k = 0; k < 2 * shell_segments; ++k) {
    const double* p = &points[3 * static_cast<std::size_t>(k)];
    EXPECT_NEAR(std::hypot(p[0], p[1]), 0.45, 1e-15);
    EXPECT_EQ(p[2], k < shell_segments ? 0.0 : flat.walls().mill->length);
  }
  // A periodic slab has no ends.
  const World<3> slab = example_world<3>(
      {"simulation.dimension=3", "mill.length=0.9", "mill.periodic=true", "mill.slab_length=0.16"},
      0);
  EXPECT_EQ(polys_of(slab), shell_segments + 6 * 8);
  // Conical ends: each a ring of quadrilaterals to the trunnion, closed there by a plate at
  // r_t = R − c / tan α, c beyond the cylinder.
  const World<3> cones = example_world<3>(
      {"simulation.dimension=3", "mill.cone_angle=20", "mill.cone_length=0.05"}, 0);
  EXPECT_EQ(polys_of(cones), 3 * shell_segments + 6 * 8 + 2);
  const std::string cone_file = mill_vtp(cones);
  const std::vector<double> cone_points = array_of(cone_file, "NumberOfComponents=\"3\" format");
  const double trunnion = 0.45 - 0.05 / std::tan(20.0 * pi / 180.0);
  const auto segments = static_cast<std::size_t>(shell_segments);
  const std::size_t first_trunnion = 2 * segments + std::size_t{8} * 8;  // 8 lifters, 8 corners
  ASSERT_EQ(cone_points.size(), 3 * (first_trunnion + 2 * segments));
  for (std::size_t k = first_trunnion; k < first_trunnion + 2 * segments; ++k) {
    const double* p = &cone_points[3 * k];
    EXPECT_NEAR(std::hypot(p[0], p[1]), trunnion, 1e-14);
    EXPECT_EQ(p[2],
              k < first_trunnion + shell_segments ? -0.05 : cones.walls().mill->length + 0.05);
  }
}

/// The polygons of a mill file: each one's corners, and its wall (0 shell, 1 lifter, 2 end).
struct Polygons {
  std::vector<std::vector<std::array<double, 3>>> corners;
  std::vector<int> wall;
};

Polygons polygons_of(std::string_view file) {
  const std::vector<double> points = array_of(file, "NumberOfComponents=\"3\" format");
  const std::string_view polys = file.substr(file.find("<Polys>"));
  const std::vector<double> connectivity = array_of(polys, "Name=\"connectivity\"");
  const std::vector<double> offsets = array_of(polys, "Name=\"offsets\"");
  const std::vector<double> wall = array_of(file, "Name=\"wall\"");
  Polygons out;
  std::size_t start = 0;
  for (const double end : offsets) {
    std::vector<std::array<double, 3>> corners;
    for (auto k = start; k < static_cast<std::size_t>(end); ++k) {
      const auto p = 3 * static_cast<std::size_t>(connectivity[k]);
      corners.push_back({points[p], points[p + 1], points[p + 2]});
    }
    out.corners.push_back(corners);
    start = static_cast<std::size_t>(end);
  }
  // The wall array holds the lines' values first (none in 3D), then the polygons'.
  const std::size_t lines = wall.size() - offsets.size();
  for (std::size_t k = lines; k < wall.size(); ++k) out.wall.push_back(static_cast<int>(wall[k]));
  return out;
}

std::array<double, 3> centroid(const std::vector<std::array<double, 3>>& corners) {
  std::array<double, 3> c{};
  for (const auto& p : corners) {
    for (std::size_t k = 0; k < 3; ++k) c[k] += p[k] / static_cast<double>(corners.size());
  }
  return c;
}

/// Newell's normal of a polygon: by the right-hand rule over its corners' order.
std::array<double, 3> normal_of(const std::vector<std::array<double, 3>>& corners) {
  std::array<double, 3> n{};
  for (std::size_t k = 0; k < corners.size(); ++k) {
    const auto& a = corners[k];
    const auto& b = corners[(k + 1) % corners.size()];
    n[0] += (a[1] - b[1]) * (a[2] + b[2]);
    n[1] += (a[2] - b[2]) * (a[0] + b[0]);
    n[2] += (a[0] - b[0]) * (a[1] + b[1]);
  }
  return n;
}

double dot3(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

std::array<double, 3> minus3(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}

TEST(VtkOutput, ThreeDimensionalLiftersAreTheContactGeometrysBoxes) {
  // Lifter j's box: radial a ∈ {R − h, R}, tangential b = ±w/2 about the direction
  // 0.3 + 2πj/8, z ∈ {0, L} (mill_geometry.cpp's frame), for the mill turned to 0.3 rad.
  World<3> world = example_world<3>({"simulation.dimension=3"}, 0);
  world.walls().mill->turn_to(0.3);
  const Polygons mesh = polygons_of(mill_vtp(world));
  const double length = world.walls().mill->length;
  int lifter_faces = 0;
  for (std::size_t k = 0; k < mesh.corners.size(); ++k) {
    if (mesh.wall[k] != 1) continue;
    const int j = lifter_faces++ / 6;
    const double angle = 0.3 + 2.0 * pi * j / 8.0;
    for (const auto& p : mesh.corners[k]) {
      const double a = p[0] * std::cos(angle) + p[1] * std::sin(angle);
      const double b = -p[0] * std::sin(angle) + p[1] * std::cos(angle);
      EXPECT_TRUE(std::abs(a - 0.41) < 1e-15 || std::abs(a - 0.45) < 1e-15) << a;
      EXPECT_NEAR(std::abs(b), 0.02, 1e-15);
      EXPECT_TRUE(p[2] == 0.0 || p[2] == length) << p[2];
    }
  }
  EXPECT_EQ(lifter_faces, 6 * 8);
}

TEST(VtkOutput, PolygonsFaceOutOfTheMillAndOutOfEachLiftersBox) {
  for (const auto& overrides : std::vector<std::vector<std::string>>{
           {"simulation.dimension=3"},
           {"simulation.dimension=3", "mill.cone_angle=20", "mill.cone_length=0.05"}}) {
    const World<3> world = example_world<3>(overrides, 0);
    const Polygons mesh = polygons_of(mill_vtp(world));
    // The mill's inside is convex: out of it is away from its centre on the axis.
    const std::array<double, 3> middle{0.0, 0.0, 0.5 * world.walls().mill->length};
    std::vector<std::size_t> box;
    for (std::size_t k = 0; k < mesh.corners.size(); ++k) {
      const auto n = normal_of(mesh.corners[k]);
      if (mesh.wall[k] != 1) {
        EXPECT_GT(dot3(n, minus3(centroid(mesh.corners[k]), middle)), 0.0)
            << "wall " << mesh.wall[k] << " polygon " << k << " faces into the mill";
        continue;
      }
      box.push_back(k);
      if (box.size() < 6) continue;
      // A lifter's six faces: each away from the box's centre.
      std::array<double, 3> box_centre{};
      for (const std::size_t f : box) {
        const auto c = centroid(mesh.corners[f]);
        for (std::size_t d = 0; d < 3; ++d) box_centre[d] += c[d] / 6.0;
      }
      for (const std::size_t f : box) {
        EXPECT_GT(dot3(normal_of(mesh.corners[f]), minus3(centroid(mesh.corners[f]), box_centre)),
                  0.0)
            << "lifter face " << f << " faces into its box";
      }
      box.clear();
    }
  }
}

TEST(VtkOutput, TheCollectionIsWholeAfterEverySnapshot) {
  const std::filesystem::path directory = testing::fresh_directory("vtk");
  const std::filesystem::path path = directory / "snapshots.pvd";
  {
    PvdCollection collection(path);
    collection.add(0.0, {"snapshot_000000.vtp", "mill_000000.vtp"});
    const std::string head =
        "<?xml version=\"1.0\"?>\n"
        "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
        "  <Collection>\n"
        "    <DataSet timestep=\"0\" group=\"\" part=\"0\" file=\"snapshot_000000.vtp\"/>\n"
        "    <DataSet timestep=\"0\" group=\"\" part=\"1\" file=\"mill_000000.vtp\"/>\n";
    const std::string tail = "  </Collection>\n</VTKFile>\n";
    EXPECT_EQ(read_all(path), head + tail);
    collection.add(0.05, {"snapshot_000001.vtp", "mill_000001.vtp"});
    EXPECT_EQ(read_all(path), head +
                                  "    <DataSet timestep=\"0.05\" group=\"\" part=\"0\" "
                                  "file=\"snapshot_000001.vtp\"/>\n"
                                  "    <DataSet timestep=\"0.05\" group=\"\" part=\"1\" "
                                  "file=\"mill_000001.vtp\"/>\n" +
                                  tail);
  }
  std::filesystem::remove_all(directory);
}

/// What `write` throws (its message; empty if nothing) while the process may write no file
/// beyond `limit` bytes. SIGXFSZ is ignored meanwhile, so that a write past the limit fails
/// with EFBIG instead of ending the process.
std::string message_under_file_size_limit(rlim_t limit, const std::function<void()>& write) {
  rlimit saved{};
  if (getrlimit(RLIMIT_FSIZE, &saved) != 0) return "getrlimit failed";
  const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit small = saved;
  small.rlim_cur = limit;
  std::string message;
  if (setrlimit(RLIMIT_FSIZE, &small) != 0) {
    message = "setrlimit failed";
  } else {
    try {
      write();
    } catch (const std::runtime_error& e) {
      message = e.what();
    }
    setrlimit(RLIMIT_FSIZE, &saved);
  }
  std::signal(SIGXFSZ, old_handler);
  return message;
}

TEST(VtkOutput, ACollectionWhoseWriteFailsIsLeftWholeWithWhatItListed) {
  // A file-size limit the collection's third entry passes.
  const std::filesystem::path directory = testing::fresh_directory("vtk");
  const std::filesystem::path path = directory / "particles.pvd";
  const std::string entry = "snapshot_000000.vtp";
  std::string whole_after_two;
  std::string message;
  {
    PvdCollection collection(path);
    collection.add(0.0, {entry});
    collection.add(0.05, {entry});
    whole_after_two = read_all(path);
    message = message_under_file_size_limit(whole_after_two.size() + 10,
                                            [&] { collection.add(0.1, {entry}); });
  }
  EXPECT_EQ(message, path.string() + ": write failed: " +
                         std::make_error_code(std::errc::file_too_large).message());
  EXPECT_EQ(read_all(path), whole_after_two);
  std::filesystem::remove_all(directory);
}

TEST(VtkOutput, ASnapshotIndexWhoseWriteFailsKeepsWholeRowsOnly) {
  // The same limit on index.csv (a full disk left it with half a row: "90,snapshot"). One
  // still disc, so that each snapshot file (about 60 bytes) stays below the limit and the
  // index's third row is the write that meets it.
  const std::filesystem::path directory = testing::fresh_directory("snapshots");
  const std::filesystem::path index = directory / "index.csv";
  WorldSettings<2> settings;
  settings.time_step = 1e-3;
  World<2> world(settings, Walls<2>{});
  world.particles().add(Vec2{}, 0.01, 0.002);
  std::string whole_after_two;
  std::string message;
  {
    SnapshotWriter snapshots(directory);
    snapshots.write(world);
    world.step();
    snapshots.write(world);
    whole_after_two = read_all(index);
    world.step();
    message =
        message_under_file_size_limit(whole_after_two.size() + 10, [&] { snapshots.write(world); });
  }
  EXPECT_EQ(message, index.string() + ": write failed: " +
                         std::make_error_code(std::errc::file_too_large).message());
  EXPECT_TRUE(std::filesystem::exists(directory / "snapshot_000002.csv"))
      << "the snapshot file should have fitted; the index's row was to fail";
  EXPECT_EQ(std::count(whole_after_two.begin(), whole_after_two.end(), '\n'), 3);
  EXPECT_EQ(read_all(index), whole_after_two);
  std::filesystem::remove_all(directory);
}

TEST(VtkOutput, AFileWhoseWriteFailsSaysWhy) {
  const std::filesystem::path directory = testing::fresh_directory("vtk");
  const std::string message = message_under_file_size_limit(
      1000, [&] { write_whole_file(directory / "snapshot_000000.vtp", std::string(5000, 'x')); });
  EXPECT_EQ(message, (directory / "snapshot_000000.vtp").string() + ": write failed: " +
                         std::make_error_code(std::errc::file_too_large).message());
  EXPECT_FALSE(std::filesystem::exists(directory / "snapshot_000000.vtp.partial"));
  std::filesystem::remove_all(directory);
}

TEST(VtkOutput, SnapshotsInVtkOnlyWriteNoTableAndTheIndexNamesTheirFiles) {
  const std::filesystem::path directory = testing::fresh_directory("vtk");
  World<2> world = example_world<2>({}, 0);
  {
    SnapshotWriter snapshots(directory, false, true);
    snapshots.write(world);
    for (int n = 0; n < 10; ++n) world.step();
    snapshots.write(world);
  }
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(directory)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  EXPECT_EQ(names, (std::vector<std::string>{"index.csv", "mill.pvd", "mill_000000.vtp",
                                             "mill_000001.vtp", "particles.pvd",
                                             "snapshot_000000.vtp", "snapshot_000001.vtp"}));
  EXPECT_NE(read_all(directory / "particles.pvd").find("part=\"0\" file=\"snapshot_000001.vtp\""),
            std::string::npos);
  EXPECT_NE(read_all(directory / "mill.pvd").find("part=\"0\" file=\"mill_000001.vtp\""),
            std::string::npos);
  const std::string index = read_all(directory / "index.csv");
  EXPECT_TRUE(
      index.starts_with("snapshot,file,time_s,shell_angle_rad\n0,snapshot_000000.vtp,0,0\n"
                        "1,snapshot_000001.vtp,"))
      << index;
  std::filesystem::remove_all(directory);
}

}  // namespace
}  // namespace millsim
