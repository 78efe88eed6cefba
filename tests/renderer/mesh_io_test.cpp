// Mesh files: a real OBJ (glmark2's bunny), tiny OBJ/PLY assets with the
// awkward parts of each format, binary PLY in both byte orders built here,
// and malformed or truncated files, which must raise MeshError naming the
// file, never crash.
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <glm/common.hpp>

#include "camhead/renderer/mesh_io.h"
#include "test_support.h"

#include <gtest/gtest.h>

namespace camhead::renderer {
namespace {

namespace fs = std::filesystem;

const fs::path kAssets = fs::path(CAMHEAD_SOURCE_DIR) / "tests" / "assets";
const fs::path kBunny = "/usr/share/glmark2/models/bunny.obj";

// The pentagon of assets/pentagon.ply: five corners, fanned from corner 0.
const std::vector<glm::vec3> kPentagon = {{0.0f, 0.0f, 0.0f},
                                          {1.0f, 0.0f, 0.0f},
                                          {1.5f, 1.0f, 0.0f},
                                          {0.5f, 1.5f, 0.0f},
                                          {-0.5f, 1.0f, 0.0f}};
const std::vector<glm::uvec3> kPentagonFan = {{0, 1, 2}, {0, 2, 3}, {0, 3, 4}};

// Values in the byte order of a binary PLY body.
class Body {
public:
  explicit Body(bool big_endian) : big_(big_endian) {}
  template <typename T> Body &put(T v) {
    char b[sizeof(T)];
    std::memcpy(b, &v, sizeof v);
    if (big_ != (std::endian::native == std::endian::big))
      std::reverse(b, b + sizeof v);
    bytes.append(b, sizeof v);
    return *this;
  }
  std::string bytes;

private:
  bool big_;
};

// The asset pentagon again, with other types and other extra data.
std::string binary_pentagon(bool big_endian) {
  std::string ply = std::string("ply\nformat ") +
                    (big_endian ? "binary_big_endian" : "binary_little_endian") +
                    " 1.0\n"
                    "element edge 2\nproperty int a\nproperty int b\n"
                    "element vertex 5\nproperty double x\nproperty short s\nproperty double y\n"
                    "property float z\nproperty list ushort int8 extra\n"
                    "element face 1\nproperty list uchar uint vertex_indices\nproperty int flags\n"
                    "end_header\n";
  Body b(big_endian);
  b.put<std::int32_t>(0).put<std::int32_t>(1).put<std::int32_t>(1).put<std::int32_t>(2);
  for (const glm::vec3 &p : kPentagon) {
    b.put<double>(p.x).put<std::int16_t>(-7).put<double>(p.y).put<float>(p.z);
    b.put<std::uint16_t>(2).put<std::int8_t>(-1).put<std::int8_t>(1);
  }
  b.put<std::uint8_t>(5);
  for (std::uint32_t i = 0; i < 5; ++i)
    b.put<std::uint32_t>(i);
  b.put<std::int32_t>(42);
  return ply + b.bytes;
}

class MeshIo : public ::testing::Test {
protected:
  fs::path write(const std::string &name, const std::string &bytes) const {
    return scratch_.write(name, bytes);
  }
  // The MeshError message for `bytes` stored as `name`; empty if it loads.
  std::string error_for(const std::string &name, const std::string &bytes) const {
    const fs::path path = write(name, bytes);
    try {
      (void)load_mesh(path);
    } catch (const MeshError &e) {
      EXPECT_EQ(std::string(e.what()).rfind(path.string() + ": ", 0), 0u) << e.what();
      return e.what();
    }
    return {};
  }

  test::ScratchDir scratch_;
  const fs::path dir_ = scratch_.path();
};

TEST_F(MeshIo, LoadsTheBunnyObj) {
  if (!fs::exists(kBunny))
    GTEST_SKIP() << "glmark2-data is not installed";
  const TriangleMesh m = load_mesh(kBunny);
  EXPECT_EQ(m.positions.size(), 34835u);
  EXPECT_EQ(m.triangles.size(), 69666u);
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3 &p : m.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  EXPECT_NEAR(lo.x, -1.0f, 0.02f);
  EXPECT_NEAR(hi.x, 1.0f, 0.02f);
  EXPECT_EQ(m.positions.front(), glm::vec3(0.296502f, -0.907931f, 0.450151f));
  EXPECT_EQ(m.triangles.front(), glm::uvec3(0, 1, 2));
}

TEST_F(MeshIo, FanTriangulatesObjPolygonsAndResolvesRelativeIndices) {
  const TriangleMesh m = load_mesh(kAssets / "quad.obj");
  ASSERT_EQ(m.positions.size(), 5u);
  EXPECT_EQ(m.positions[4], glm::vec3(0.5f, 1.0f, -0.5f));
  const std::vector<glm::uvec3> expected = {{0, 1, 2}, {0, 2, 3}, {0, 1, 4}};
  EXPECT_EQ(m.triangles, expected);
}

TEST_F(MeshIo, ReadsAsciiPlySkippingOtherData) {
  const TriangleMesh m = load_mesh(kAssets / "pentagon.ply");
  EXPECT_EQ(m.positions, kPentagon);
  EXPECT_EQ(m.triangles, kPentagonFan);
}

TEST_F(MeshIo, ReadsBinaryPlyInBothByteOrders) {
  for (const bool big : {false, true}) {
    const TriangleMesh m = load_mesh(write("pentagon.PLY", binary_pentagon(big)));
    EXPECT_EQ(m.positions, kPentagon) << (big ? "big" : "little") << " endian";
    EXPECT_EQ(m.triangles, kPentagonFan) << (big ? "big" : "little") << " endian";
  }
  // CRLF header lines, as written on Windows.
  std::string crlf = binary_pentagon(false);
  for (std::size_t at = crlf.find('\n'); at < crlf.find("end_header"); at = crlf.find('\n', at + 2))
    crlf.insert(at, "\r");
  crlf.insert(crlf.find("end_header") + 10, "\r");
  EXPECT_EQ(load_mesh(write("crlf.ply", crlf)).triangles, kPentagonFan);
}

// What a triangle mesh does not use is left out before tinyobjloader reads
// the file: texture and normal indices, and vertex weights, whose `vw c 1e60`
// made it convert an out-of-range float to int (UBSan).
TEST_F(MeshIo, ObjKeepsPositionsAndFacesOnly) {
  const std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\nvw c 1e60\n"
                          "mtllib none.mtl\nusemtl x\ng part\nf 1/1/1 2//1 -1\n";
  const TriangleMesh m = load_mesh(write("extras.obj", obj));
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_EQ(m.triangles[0], glm::uvec3(0, 1, 2));
}

// What tests/fuzz found (tinyobjloader's float-to-int conversion on `vw`
// lines): each file loads or is refused with MeshError, and nothing else.
TEST_F(MeshIo, FuzzFindingsLoadOrAreRefused) {
  for (const char *name : {"obj_vw_float_to_int_1.obj", "obj_vw_float_to_int_2.obj",
                           "obj_vw_float_to_int_3.obj", "obj_vw_behind_cr.obj"}) {
    try {
      (void)load_mesh(test::source_dir() / "tests/assets/fuzz" / name);
    } catch (const MeshError &) {
    }
  }
}

// tinyobjloader ends a line at a lone "\r" too (old Mac files), and so must
// the filter in front of it, or a line behind a "\r" reaches it unchecked
// (a `vw` line did, tests/assets/fuzz/obj_vw_behind_cr.obj).
TEST_F(MeshIo, CarriageReturnsEndLines) {
  const TriangleMesh lf = load_mesh(write("lf.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"));
  const TriangleMesh cr = load_mesh(write("cr.obj", "v 0 0 0\rv 1 0 0\rv 0 1 0\rf 1 2 3\r"));
  EXPECT_EQ(cr.positions, lf.positions);
  EXPECT_EQ(cr.triangles, lf.triangles);
  const fs::path bad = write("bad.obj", "v 0 0 0\r\nv 1 0 0\rv 0 1 0\nf 1 2 9\r");
  try {
    (void)load_mesh(bad);
    ADD_FAILURE() << "loaded";
  } catch (const MeshError &e) {
    EXPECT_EQ(std::string(e.what()),
              bad.string() + ": line 4: face vertex 9 is not one of the 3 positions");
  }
}

TEST_F(MeshIo, RejectsMalformedObj) {
  const std::string v3 = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  // Refused at its line, before tinyobjloader stores a garbage face.
  EXPECT_NE(
      error_for("index.obj", v3 + "f 1 2 4\n").find("line 4: face vertex 4 is not one of the 3"),
      std::string::npos);
  EXPECT_NE(error_for("word.obj", v3 + "f 1 2 x\n").find("line 4: face vertex 'x'"),
            std::string::npos);
  EXPECT_NE(error_for("zero.obj", v3 + "f 0 1 2\n").find("line 4"), std::string::npos);
  EXPECT_NE(error_for("relative.obj", v3 + "f -1 -2 -4\n"), "");
  EXPECT_NE(error_for("empty.obj", "").find("no faces"), std::string::npos);
  EXPECT_NE(error_for("points.obj", v3 + "l 1 2\n").find("no faces"), std::string::npos);
  EXPECT_NE(error_for("inf.obj", "v 1e39 0 0\n" + v3 + "f 2 3 4\n").find("vertex 0"),
            std::string::npos);
  EXPECT_NE(error_for("exp.obj", "v 1e2147483649 0 0\n" + v3).find("line 1"), std::string::npos);
  EXPECT_NE(error_for("mesh.stl", v3 + "f 1 2 3\n").find("unsupported"), std::string::npos);
  EXPECT_THROW((void)load_mesh(dir_ / "missing.obj"), MeshError);
  // A face with more corners than tinyobjloader can count (255).
  std::string big = v3, face = "f";
  for (int i = 0; i < 300; ++i)
    face += " " + std::to_string(1 + i % 3);
  EXPECT_NE(error_for("big.obj", big + face + "\n"), "");
}

TEST_F(MeshIo, RejectsMalformedPly) {
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                           "property float y\nproperty float z\n";
  const std::string face = "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string verts = "0 0 0\n1 0 0\n0 1 0\n";
  ASSERT_EQ(error_for("ok.ply", head + face + verts + "3 0 1 2\n"), "");
  const std::pair<std::string, std::string> cases[] = {
      {"not a PLY file", "obj\n" + head.substr(4) + face + verts},
      {"no end_header", head},
      {"header line 2: bad format", "ply\nformat ascii\n" + head.substr(21) + face},
      {"bad format", "ply\nformat binary 1.0\n" + head.substr(21) + face},
      {"header line 4: bad property", head.substr(0, 38) + "property half x\n" + face},
      {"unknown keyword", head + "elements face 1\n" + face},
      {"element vertex: needs properties x, y and z", head.substr(0, 72) + face + verts},
      {"element face: needs a list", head + "element face 1\nproperty int a\nend_header\n"},
      {"element face: needs one integer list",
       head + "element face 1\nproperty list uchar float vertex_indices\nend_header\n"},
      {"element vertex: truncated at item 2 of 3", head + face + "0 0 0\n1 0 0\n0 1"},
      {"element face: truncated at item 0 of 1", head + face + verts + "3 0 1"},
      {"element face: bad value in item 0", head + face + verts + "3 0 1 x\n"},
      {"element face: bad value in item 0", head + face + verts + "3 0 -1 2\n"},
      {"element face: bad value in item 0", head + face + verts + "300 0 1 2\n"},
      {"element vertex: bad value in item 1", head + face + "0 0 0\n1 1e999 0\n0 1 0\n3 0 1 2\n"},
      {"triangle 0 references a vertex", head + face + verts + "3 0 1 3\n"},
      {"needs a vertex and a face", head + "end_header\n" + verts},
      {"no faces", head + face + verts + "2 0 1\n"},
  };
  for (const auto &[expected, text] : cases) {
    const std::string msg = error_for("bad.ply", text);
    EXPECT_NE(msg.find(expected), std::string::npos)
        << "expected '" << expected << "', got '" << msg << "' for\n"
        << text;
  }
  // A huge count of an element that has no properties occupies no bytes.
  EXPECT_EQ(error_for("empty_elem.ply",
                      head + "element junk 18446744073709551615\n" + face + verts + "3 0 1 2\n"),
            "");
  // A vertex count far beyond the data must not allocate it, just fail.
  std::string huge = binary_pentagon(false);
  huge.replace(huge.find("vertex 5"), 8, "vertex 4000000000");
  EXPECT_NE(error_for("huge.ply", huge).find("element vertex: truncated"), std::string::npos);
}

TEST_F(MeshIo, TruncatedOrCorruptedFilesNeverCrash) {
  for (const bool big : {false, true}) {
    const std::string ply = binary_pentagon(big);
    const std::size_t body = ply.find("end_header\n") + 11;
    for (std::size_t n = 0; n < ply.size(); ++n) {
      const std::string msg = error_for("cut.ply", ply.substr(0, n));
      EXPECT_NE(msg, "") << n;
      if (n >= body) {
        EXPECT_NE(msg.find("element"), std::string::npos) << msg;
      }
    }
    for (std::size_t i = 0; i < ply.size(); ++i) {
      for (const char c : {'\0', '\xff', ' '}) {
        std::string t = ply;
        t[i] = c;
        (void)error_for("flip.ply", t); // either loads or throws MeshError
      }
    }
  }
  std::ifstream in(kAssets / "quad.obj", std::ios::binary);
  const std::string obj((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t n = 0; n < obj.size(); ++n)
    (void)error_for("cut.obj", obj.substr(0, n));
}

} // namespace
} // namespace camhead::renderer
