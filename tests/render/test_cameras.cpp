// Camera files for `vtbake validate --cameras`: parsing, defaults and every rejected input.
#include <gtest/gtest.h>

#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "render/camera.h"
#include "render/validate.h"

namespace vt::render {
namespace {

constexpr float kAspect = 16.0f / 9.0f;

// Clip-space position of a world point.
std::array<float, 4> project(const Mat4& m, Vec3f p) {
  std::array<float, 4> r{};
  for (int row = 0; row < 4; ++row) {
    r[row] =
        m.m[0 * 4 + row] * p.x + m.m[1 * 4 + row] * p.y + m.m[2 * 4 + row] * p.z + m.m[3 * 4 + row];
  }
  return r;
}

std::string parse_error(const std::string& text) {
  auto r = parse_cameras_json(text, "cams.json", kAspect);
  EXPECT_FALSE(r.ok()) << text;
  if (r.ok()) return "";
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidArgument) << text;
  EXPECT_EQ(r.status().message().rfind("cams.json: ", 0), 0u) << r.status().message();
  return r.status().message();
}

bool contains(const std::string& s, const std::string& part) {
  return s.find(part) != std::string::npos;
}

TEST(CameraFile, ParsesCamerasIntoTheSameMatricesAsLookAtAndPerspective) {
  auto r = parse_cameras_json(
      R"({"cameras": [
            {"eye": [0, 6, 8], "target": [0, 0, 0], "up": [0, 1, 0], "fov_y_deg": 50,
             "near": 0.5, "far": 40},
            {"eye": [-3.5, 0.25, 2], "target": [1, 0.5, -1], "fov_y_deg": 20, "near": 0.1,
             "far": 12.5}]})",
      "cams.json", kAspect);
  ASSERT_TRUE(r.ok()) << r.status().message();
  ASSERT_EQ(r->size(), 2u);
  const float deg = 3.14159265358979f / 180.0f;
  const Mat4 m0 =
      perspective(50 * deg, kAspect, 0.5f, 40) * look_at({0, 6, 8}, {0, 0, 0}, {0, 1, 0});
  const Mat4 m1 = perspective(20 * deg, kAspect, 0.1f, 12.5f) *
                  look_at({-3.5f, 0.25f, 2}, {1, 0.5f, -1}, {0, 1, 0});
  // Equal up to the rounding of the degree-to-radian conversion.
  for (int i = 0; i < 16; ++i) {
    EXPECT_NEAR((*r)[0].view_proj.m[i], m0.m[i], 1e-6f * (1 + std::abs(m0.m[i]))) << i;
    EXPECT_NEAR((*r)[1].view_proj.m[i], m1.m[i], 1e-6f * (1 + std::abs(m1.m[i]))) << i;
  }

  // The target lands in the middle of the image, in front of the camera, inside the depth range.
  auto c = project((*r)[0].view_proj, {0, 0, 0});
  EXPECT_NEAR(c[0] / c[3], 0.0f, 1e-5f);
  EXPECT_NEAR(c[1] / c[3], 0.0f, 1e-5f);
  EXPECT_GT(c[3], 0.0f);
  EXPECT_GT(c[2] / c[3], 0.0f);
  EXPECT_LT(c[2] / c[3], 1.0f);
  // World +y (up) appears towards the top of the image: Vulkan's clip y points down.
  auto above = project((*r)[0].view_proj, {0, 1, 0});
  EXPECT_LT(above[1] / above[3], -0.01f);
  // A point beyond `far` is clipped away (depth > 1).
  auto beyond = project((*r)[0].view_proj, {0, -30, -40});
  EXPECT_GT(beyond[2] / beyond[3], 1.0f);
}

TEST(CameraFile, DefaultsAreUpYFiftyDegreesAndDistanceRelativeClipPlanes) {
  auto implicit =
      parse_cameras_json(R"({"cameras":[{"eye":[3,4,0],"target":[0,0,0]}]})", "c.json", kAspect);
  // Eye-target distance 5: near 0.05, far 500.
  auto spelled = parse_cameras_json(
      R"({"cameras":[{"eye":[3,4,0],"target":[0,0,0],"up":[0,1,0],"fov_y_deg":50,
                      "near":0.05,"far":500}]})",
      "c.json", kAspect);
  ASSERT_TRUE(implicit.ok()) << implicit.status().message();
  ASSERT_TRUE(spelled.ok()) << spelled.status().message();
  for (int i = 0; i < 16; ++i) {
    EXPECT_NEAR((*implicit)[0].view_proj.m[i], (*spelled)[0].view_proj.m[i],
                1e-6f * (1 + std::abs((*spelled)[0].view_proj.m[i])))
        << i;
  }
}

TEST(CameraFile, SpecToCameraMatchesTheParser) {
  CameraSpec spec;
  spec.eye = {1, 2, 3};
  spec.target = {0, 0.5f, 0};
  spec.up = {0, 0, 1};
  spec.fov_y_deg = 35;
  spec.z_near = 0.25f;
  spec.z_far = 9;
  auto a = camera_from_spec(spec, 2.0f);
  auto b = parse_cameras_json(
      R"({"cameras":[{"eye":[1,2,3],"target":[0,0.5,0],"up":[0,0,1],"fov_y_deg":35,
                      "near":0.25,"far":9}]})",
      "c.json", 2.0f);
  ASSERT_TRUE(a.ok());
  ASSERT_TRUE(b.ok());
  EXPECT_EQ(a->view_proj.m, (*b)[0].view_proj.m);
}

TEST(CameraFile, RejectsEveryMalformedCameraWithTheFileTheCameraAndTheProblem) {
  const std::string ok = R"("eye":[0,6,8],"target":[0,0,0])";
  auto one = [](const std::string& body) { return R"({"cameras":[)" + body + "]}"; };
  struct Case {
    std::string text;
    std::string expect;
  };
  const Case cases[] = {
      {"{", "not valid JSON"},
      {"", "not valid JSON"},
      {"[]", "expected an object"},
      {R"({"views":[]})", "expected an object"},
      {R"({"cameras":{}})", "must be an array"},
      {R"({"cameras":[]})", "is empty"},
      {R"({"cameras":[{)" + ok + R"(}],"extra":1})", "unknown key \"extra\""},
      {one("42"), "camera 0: not an object"},
      {one(R"({"target":[0,0,0]})"), "camera 0: missing \"eye\""},
      {one("{" + ok + "},{\"eye\":[1,1,1]}"), "camera 1: missing \"target\""},
      {one(R"({"eye":[0,6],"target":[0,0,0]})"), "eye: expected [x, y, z]"},
      {one(R"({"eye":[0,6,8,1],"target":[0,0,0]})"), "eye: expected [x, y, z]"},
      {one(R"({"eye":"0,6,8","target":[0,0,0]})"), "eye: expected [x, y, z]"},
      {one(R"({"eye":[0,"6",8],"target":[0,0,0]})"), "eye: not a number"},
      {one(R"({"eye":[0,true,8],"target":[0,0,0]})"), "eye: not a number"},
      {one(R"({"eye":[0,6,8],"target":[0,1e39,0]})"), "target: not a finite float"},
      {one(R"({"eye":[0,6,8],"target":[0,0,0],"up":[0,-1e300,0]})"), "up: not a finite float"},
      {one(R"({"eye":[1e400,6,8],"target":[0,0,0]})"), "not valid JSON"},
      {one(R"({"eye":[1,2,3],"target":[1,2,3]})"), "camera 0: eye and target coincide"},
      {one(R"({"eye":[1e6,0,0],"target":[1000000.01,0,0]})"), "eye and target coincide"},
      {one(R"({"eye":[0,6,0],"target":[0,0,0]})"), "up is parallel to the view direction"},
      {one("{" + ok + R"(,"up":[0,0,0]})"), "up must not be zero"},
      {one("{" + ok + R"(,"fov_y_deg":0})"), "fov_y_deg must be in (0, 180)"},
      {one("{" + ok + R"(,"fov_y_deg":180})"), "fov_y_deg must be in (0, 180)"},
      {one("{" + ok + R"(,"fov_y_deg":-30})"), "fov_y_deg must be in (0, 180)"},
      {one("{" + ok + R"(,"fov_y_deg":"wide"})"), "fov_y_deg: not a number"},
      {one("{" + ok + R"(,"near":0})"), "near must be > 0"},
      {one("{" + ok + R"(,"near":-1,"far":10})"), "near must be > 0"},
      {one("{" + ok + R"(,"far":-1})"), "far must be > 0"},
      {one("{" + ok + R"(,"near":5,"far":5})"), "must be greater than near"},
      {one("{" + ok + R"(,"near":2000})"), "must be greater than near"},
      {one("{" + ok + R"(,"fov":60})"), "camera 0: unknown key \"fov\""},
      {one(R"({"eye":[0,3e38,0],"target":[3e38,-3e38,0],"near":1,"far":1e38})"), "not finite"},
  };
  for (const Case& c : cases) {
    const std::string msg = parse_error(c.text);
    EXPECT_TRUE(contains(msg, c.expect)) << c.text << "\n  gave: " << msg;
  }
}

// Hostile input: byte mutations of a valid file give either cameras with finite matrices or an
// error naming the file, never a crash or a NaN.
TEST(CameraFile, MutatedFilesGiveFiniteCamerasOrErrors) {
  const std::string base =
      R"({"cameras":[{"eye":[0,6,8],"target":[0,0,0],"up":[0,1,0],"fov_y_deg":50,)"
      R"("near":0.1,"far":100},{"eye":[-2.5e3,1,0.5],"target":[1,2,3]}]})";
  const char kBytes[] = "0123456789.-+eE[]{},:\"x ";
  uint64_t state = 0x9E3779B97F4A7C15ull;
  auto next = [&] {
    state ^= state << 13, state ^= state >> 7, state ^= state << 17;
    return state;
  };
  int parsed = 0;
  for (int i = 0; i < 3000; ++i) {
    std::string text = base;
    for (int k = 0, n = 1 + int(next() % 3); k < n; ++k) {
      text[next() % text.size()] = kBytes[next() % (sizeof(kBytes) - 1)];
    }
    auto r = parse_cameras_json(text, "m.json", kAspect);
    if (!r.ok()) {
      EXPECT_EQ(r.status().message().rfind("m.json: ", 0), 0u) << r.status().message();
      continue;
    }
    ++parsed;
    for (const Camera& c : *r) {
      for (float v : c.view_proj.m) ASSERT_TRUE(std::isfinite(v)) << text;
    }
  }
  // Mutations that only change a digit still parse: the loop exercises both outcomes.
  EXPECT_GT(parsed, 100);
  EXPECT_LT(parsed, 3000);
}

TEST(CameraFile, LimitsTheNumberOfCameras) {
  std::string body;
  for (size_t i = 0; i < kMaxFileCameras; ++i) {
    body += std::string(i ? "," : "") + R"({"eye":[)" + std::to_string(i + 1) +
            R"(,2,3],"target":[0,0,0]})";
  }
  auto max = parse_cameras_json(R"({"cameras":[)" + body + "]}", "c.json", kAspect);
  ASSERT_TRUE(max.ok()) << max.status().message();
  EXPECT_EQ(max->size(), kMaxFileCameras);
  body += R"(,{"eye":[1,2,3],"target":[0,0,0]})";
  EXPECT_TRUE(contains(parse_error(R"({"cameras":[)" + body + "]}"), "257 cameras, at most 256"));
}

TEST(CameraFile, LoadsFromDiskAndNamesTheFileInErrors) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("vt_cameras_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string good = (dir / "good.json").string(), bad = (dir / "bad.json").string(),
                    huge = (dir / "huge.json").string();
  std::ofstream(good) << R"({"cameras":[{"eye":[0,6,8],"target":[0,0,0]}]})";
  std::ofstream(bad) << R"({"cameras":[{"eye":[0,6,8],"target":[0,6,8]}]})";
  {
    std::ofstream h(huge);
    h << R"({"cameras":[{"eye":[0,6,8],"target":[0,0,0]}]})";
    h << std::string(2 << 20, ' ');  // valid JSON, but beyond the 1 MiB bound
  }
  auto g = load_cameras_json(good, kAspect);
  ASSERT_TRUE(g.ok()) << g.status().message();
  EXPECT_EQ(g->size(), 1u);

  auto b = load_cameras_json(bad, kAspect);
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(b.status().message(), bad + ": camera 0: eye and target coincide");

  auto h = load_cameras_json(huge, kAspect);
  ASSERT_FALSE(h.ok());
  EXPECT_TRUE(contains(h.status().message(), huge + ": camera file larger than 1 MiB"));

  auto missing = load_cameras_json((dir / "missing.json").string(), kAspect);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.status().code(), ErrorCode::kNotFound);
  EXPECT_TRUE(contains(missing.status().message(), "missing.json"));

  auto directory = load_cameras_json(dir.string(), kAspect);
  EXPECT_FALSE(directory.ok());
  std::filesystem::remove_all(dir);
}

// A camera file can point a view at nothing: such a view must fail, not pass as identical.
TEST(CameraFile, ViewWithNoComparedPixelFails) {
  ViewMetrics m;
  m.pixels = 0;
  m.psnr_rgb = m.worst_tile_psnr = 100;  // what compare_view reports for an empty comparison
  m.ssim = 1;
  const auto why = check_view(m, scene_thresholds());
  ASSERT_EQ(why.size(), 1u);
  EXPECT_TRUE(contains(why[0], "no pixel drawn by both renders")) << why[0];
  m.pixels = 1;
  EXPECT_TRUE(check_view(m, scene_thresholds()).empty());
}

}  // namespace
}  // namespace vt::render
