// write_mesh: writer -> reader round trips for every format (binary bit-exact, ascii exact
// through shortest round-trip numbers), refusal of non-finite input and unknown extensions.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

#include "core/error.hpp"
#include "io/mesh_reader.hpp"
#include "io/mesh_writer.hpp"

namespace levelset {
namespace {

std::filesystem::path scratch_dir() {
  const char* env = std::getenv("LEVELSET_TMP");
  std::filesystem::path dir = env != nullptr && *env != '\0'
                                  ? std::filesystem::path(env)
                                  : std::filesystem::temp_directory_path() / "levelset-test";
  std::filesystem::create_directories(dir);
  return dir;
}

bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

// A mesh with awkward doubles: many digits, tiny, huge, subnormal, negative zero.
TriangleMesh awkward_mesh() {
  TriangleMesh m;
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) m.vertices.push_back({u(rng), u(rng) * 1e-7, u(rng) * 1e12});
  m.vertices.push_back({0.1, 1.0 / 3.0, -0.0});
  m.vertices.push_back(
      {std::numeric_limits<double>::denorm_min(), -1e-310, std::numeric_limits<double>::max()});
  m.vertices.push_back({std::numeric_limits<double>::lowest(), 5e-324, 123456789.123456789});
  std::uniform_int_distribution<std::uint32_t> pick(
      0, static_cast<std::uint32_t>(m.vertices.size() - 1));
  for (int t = 0; t < 400; ++t) m.triangles.push_back({pick(rng), pick(rng), pick(rng)});
  return m;
}

void expect_identical(const TriangleMesh& a, const TriangleMesh& b) {
  ASSERT_EQ(a.vertices.size(), b.vertices.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (std::size_t i = 0; i < a.vertices.size(); ++i)
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(same_bits(a.vertices[i][k], b.vertices[i][k]))
          << "vertex " << i << " axis " << k << ": " << a.vertices[i][k] << " vs "
          << b.vertices[i][k];
  EXPECT_EQ(a.triangles, b.triangles);
}

TEST(MeshWriter, RoundTripsExactlyThroughOffObjPlyTria) {
  const TriangleMesh mesh = awkward_mesh();
  struct Case {
    const char* name;
    bool binary;
    MeshFormat format;
  };
  for (const Case& c :
       {Case{"m.off", false, MeshFormat::Off}, Case{"m.obj", false, MeshFormat::Obj},
        Case{"m.ply", true, MeshFormat::PlyBinaryLittleEndian},
        Case{"m.ply", false, MeshFormat::PlyAscii}, Case{"m.tria", false, MeshFormat::Tria}}) {
    SCOPED_TRACE(std::string(c.name) + (c.binary ? " binary" : " ascii"));
    MeshWriteOptions options;
    options.binary = c.binary;
    const std::string bytes = write_mesh_to_memory(mesh, c.name, options);
    const MeshReadResult r = read_mesh_from_memory(bytes, c.name);
    EXPECT_EQ(r.format, c.format);
    expect_identical(mesh, r.mesh);
    // Writing what was read gives the same bytes again.
    EXPECT_EQ(write_mesh_to_memory(r.mesh, c.name, options), bytes);
  }
}

// STL keeps no shared vertices and stores float32 (binary): use float-representable
// coordinates, every vertex used, no duplicates; the reader welds them back in first-use order.
TriangleMesh float_mesh() {
  TriangleMesh m;
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-100.f, 100.f);
  for (int i = 0; i < 300; ++i)
    m.vertices.push_back(
        {static_cast<double>(u(rng)), static_cast<double>(u(rng)), static_cast<double>(u(rng))});
  for (std::uint32_t i = 0; i + 2 < 300; i += 3) m.triangles.push_back({i, i + 1, i + 2});
  for (std::uint32_t i = 0; i + 5 < 300; i += 5) m.triangles.push_back({i + 5, i, i + 3});
  return m;
}

TEST(MeshWriter, StlRoundTripsBinaryBitExactAndAsciiExact) {
  const TriangleMesh mesh = float_mesh();
  for (const bool binary : {true, false}) {
    SCOPED_TRACE(binary ? "binary" : "ascii");
    MeshWriteOptions options;
    options.binary = binary;
    const std::string bytes = write_mesh_to_memory(mesh, "m.stl", options);
    if (binary) {
      EXPECT_EQ(bytes.size(), 84 + 50 * mesh.triangles.size());
      EXPECT_NE(bytes.substr(0, 5), "solid");
    } else {
      EXPECT_EQ(bytes.substr(0, 5), "solid");
    }
    const MeshReadResult r = read_mesh_from_memory(bytes, "m.stl");
    EXPECT_EQ(r.format, binary ? MeshFormat::StlBinary : MeshFormat::StlAscii);
    expect_identical(mesh, r.mesh);
    EXPECT_EQ(write_mesh_to_memory(r.mesh, "m.stl", options), bytes);
  }
  // Doubles that are not floats survive ascii STL exactly.
  TriangleMesh precise;
  precise.vertices = {{0.1, 0.2, 0.3}, {1.0 / 3.0, 2.0 / 3.0, 1e-300}, {-1e300, 7.0, 1e-17}};
  precise.triangles = {{0, 1, 2}};
  MeshWriteOptions ascii;
  ascii.binary = false;
  const MeshReadResult r =
      read_mesh_from_memory(write_mesh_to_memory(precise, "p.stl", ascii), "p.stl");
  expect_identical(precise, r.mesh);
}

TEST(MeshWriter, BinaryStlNormalsAreUnitAndHeaderIsNotSolid) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  m.triangles = {{0, 1, 2}, {0, 0, 1}};  // second one degenerate: zero normal
  const std::string bytes = write_mesh_to_memory(m, "n.stl");
  float normal[3];
  std::memcpy(normal, bytes.data() + 84, 12);
  EXPECT_EQ(normal[0], 0.f);
  EXPECT_EQ(normal[1], 0.f);
  EXPECT_EQ(normal[2], 1.f);
  std::memcpy(normal, bytes.data() + 134, 12);
  EXPECT_EQ(normal[2], 0.f);
}

TEST(MeshWriter, WritesFilesAtomicallyAndReadsThemBack) {
  const TriangleMesh mesh = float_mesh();
  const auto dir = scratch_dir() / "mesh_writer";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  for (const char* name : {"a.off", "a.obj", "a.ply", "a.stl", "a.tria", "UPPER.PLY"}) {
    SCOPED_TRACE(name);
    const auto path = dir / name;
    write_mesh(mesh, path);
    const MeshReadResult r = read_mesh(path);
    expect_identical(mesh, r.mesh);
  }
  // Overwriting works and leaves no temporary files behind.
  write_mesh(mesh, dir / "a.off");
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().string().find(".tmp-"), std::string::npos) << entry.path();
    ++files;
  }
  EXPECT_EQ(files, 6);
  std::filesystem::remove_all(dir);
}

TEST(MeshWriter, EmptyMeshRoundTrips) {
  const TriangleMesh empty;
  for (const char* name : {"e.off", "e.ply", "e.stl", "e.tria", "e.obj"}) {
    SCOPED_TRACE(name);
    for (const bool binary : {true, false}) {
      MeshWriteOptions options;
      options.binary = binary;
      const MeshReadResult r =
          read_mesh_from_memory(write_mesh_to_memory(empty, name, options), name);
      EXPECT_TRUE(r.mesh.vertices.empty());
      EXPECT_TRUE(r.mesh.triangles.empty());
    }
  }
}

TEST(MeshWriter, RefusesInvalidMeshesAndUnknownExtensions) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  const auto expect_code = [](const TriangleMesh& mesh, const char* name, ErrorCode code) {
    try {
      write_mesh_to_memory(mesh, name);
      ADD_FAILURE() << name << ": no error";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), code) << e.what();
      EXPECT_EQ(e.where(), name);
    }
  };
  expect_code(m, "m.gltf", ErrorCode::UnsupportedFormat);
  expect_code(m, "m", ErrorCode::UnsupportedFormat);
  TriangleMesh bad = m;
  bad.vertices[1].y = std::numeric_limits<double>::quiet_NaN();
  for (const char* name : {"m.off", "m.obj", "m.ply", "m.stl", "m.tria"})
    expect_code(bad, name, ErrorCode::NonFinite);
  bad = m;
  bad.vertices[2].z = -std::numeric_limits<double>::infinity();
  expect_code(bad, "m.ply", ErrorCode::NonFinite);
  bad = m;
  bad.triangles[0][2] = 3;
  expect_code(bad, "m.off", ErrorCode::InvalidArgument);
  bad = m;
  bad.vertices[0].x = 1e300;  // beyond float: binary STL cannot hold it
  expect_code(bad, "m.stl", ErrorCode::LimitExceeded);
  // Nothing is written on refusal.
  const auto path = scratch_dir() / "refused.off";
  std::filesystem::remove(path);
  bad = m;
  bad.vertices[0].x = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(write_mesh(bad, path), Error);
  EXPECT_FALSE(std::filesystem::exists(path));
}

TEST(MeshWriter, OutputIsReadableByTheFormatsConventions) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.triangles = {{0, 1, 2}};
  EXPECT_EQ(write_mesh_to_memory(m, "m.off"), "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_EQ(write_mesh_to_memory(m, "m.tria"), "4\n3\n1\n0 0 0\n1 0 0\n0 1 0\n0 1 2\n");
  const std::string obj = write_mesh_to_memory(m, "m.obj");
  EXPECT_NE(obj.find("v 1 0 0\n"), std::string::npos);
  EXPECT_NE(obj.find("f 1 2 3\n"), std::string::npos);
  const std::string ply = write_mesh_to_memory(m, "m.ply");
  EXPECT_EQ(ply.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(ply.find("property list uchar int vertex_indices\nend_header\n"), std::string::npos);
}

}  // namespace
}  // namespace levelset
