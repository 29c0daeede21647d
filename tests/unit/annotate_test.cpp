#include "render/annotate.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <string>

#include "render/render_error.hpp"

namespace gvio::render {
namespace {

struct Rgb8 {
  int r, g, b;
};
constexpr Rgb8 kBackground{40, 45, 55};

ImageRgba uniform(int width, int height, Rgb8 c = kBackground) {
  ImageRgba image{width, height, {}};
  for (int i = 0; i < width * height; ++i) {
    image.rgba.insert(image.rgba.end(),
                      {static_cast<std::uint8_t>(c.r), static_cast<std::uint8_t>(c.g),
                       static_cast<std::uint8_t>(c.b), 255});
  }
  return image;
}

Annotations everything() {
  Annotations a;
  a.title = "KITTI 2011_09_26_drive_0001: estimate vs GNSS";
  a.legend = {{"estimate", {0.12F, 0.47F, 0.71F}, false},
              {"reference (GNSS)", {1.0F, 0.5F, 0.05F}, true},
              {"GNSS outage", {0.84F, 0.15F, 0.16F}, false}};
  a.color_bar = Annotations::ColorBar{ColorMap::kViridis, 0.0, 120.0, "height (m)"};
  a.metres_per_pixel = 0.5;
  a.north_deg = 30.0;
  return a;
}

Rgb8 at(const ImageRgba& image, int x, int y) {
  const std::uint8_t* p = image.pixel(x, y);
  return {p[0], p[1], p[2]};
}

bool close(Rgb8 a, Rgb8 b, int tol) {
  return std::abs(a.r - b.r) <= tol && std::abs(a.g - b.g) <= tol && std::abs(a.b - b.b) <= tol;
}

Rgb8 to8(Rgb c) {
  const auto q = [](float v) { return static_cast<int>(std::lround(v * 255.0F)); };
  return {q(c.r), q(c.g), q(c.b)};
}

// Pixels in [x0, x1) x [y0, y1) for which `pred` holds.
template <typename Pred>
int count(const ImageRgba& image, int x0, int y0, int x1, int y1, Pred pred) {
  int n = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) n += pred(at(image, x, y)) ? 1 : 0;
  }
  return n;
}

bool bright(Rgb8 c) {
  return c.r > 200 && c.g > 200 && c.b > 200;
}

bool regionUnchanged(const ImageRgba& a, const ImageRgba& b, int x0, int y0, int x1, int y1) {
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      for (int c = 0; c < 4; ++c) {
        if (a.pixel(x, y)[c] != b.pixel(x, y)[c]) return false;
      }
    }
  }
  return true;
}

TEST(Annotate, EverythingOnChangesTheImage) {
  const ImageRgba before = uniform(800, 600);
  ImageRgba image = before;
  annotate(image, everything());
  EXPECT_NE(image.rgba, before.rgba);
  EXPECT_EQ(image.width, 800);
  EXPECT_EQ(image.height, 600);
  ASSERT_EQ(image.rgba.size(), before.rgba.size());
  // The middle of the map and the bottom-right corner carry no overlay.
  EXPECT_TRUE(regionUnchanged(image, before, 300, 250, 500, 400));
  EXPECT_TRUE(regionUnchanged(image, before, 760, 560, 800, 600));
}

TEST(Annotate, TitleIsBrightAtTopCentre) {
  ImageRgba image = uniform(800, 600);
  annotate(image, everything());
  EXPECT_GT(count(image, 300, 0, 500, 50, bright), 1000);
}

TEST(Annotate, ColorBarSpansTheMapAtTheRightEdge) {
  ImageRgba image = uniform(800, 600);
  annotate(image, everything());
  const Rgb8 low = to8(colormap(ColorMap::kViridis, 0.0));
  const Rgb8 high = to8(colormap(ColorMap::kViridis, 1.0));
  int low_top = 600, high_bottom = -1;
  for (int y = 0; y < 600; ++y) {
    for (int x = 640; x < 800; ++x) {
      if (close(at(image, x, y), low, 4)) low_top = std::min(low_top, y);
      if (close(at(image, x, y), high, 4)) high_bottom = std::max(high_bottom, y);
    }
  }
  ASSERT_LT(low_top, 600) << "no viridis(0) pixel at the right edge";
  ASSERT_GE(high_bottom, 0) << "no viridis(1) pixel at the right edge";
  EXPECT_LT(high_bottom, low_top) << "high values must sit above low ones";
  EXPECT_GT(low_top - high_bottom, 100) << "the bar should be tall";
  // Nowhere else: the left part of the image has neither end colour.
  EXPECT_EQ(count(image, 0, 0, 400, 600, [&](Rgb8 c) { return close(c, high, 4); }), 0);
}

TEST(Annotate, ScaleBarAtBottomLeft) {
  const ImageRgba before = uniform(800, 600);
  ImageRgba image = before;
  Annotations a;
  a.metres_per_pixel = 0.5;  // 1/5 of 800 px is 80 m: the bar shows 50 m
  annotate(image, a);
  const Rgb8 ink{26, 26, 26};
  EXPECT_GT(count(image, 0, 500, 250, 600, bright), 200);
  EXPECT_GT(count(image, 0, 500, 250, 600, [&](Rgb8 c) { return close(c, ink, 2); }), 200);
  EXPECT_TRUE(regionUnchanged(image, before, 0, 0, 800, 450));
  EXPECT_TRUE(regionUnchanged(image, before, 300, 0, 800, 600));
}

TEST(Annotate, NorthArrowTurnsWithNorth) {
  ImageRgba up = uniform(800, 600), east = uniform(800, 600);
  Annotations a;
  a.north_deg = 0.0;
  annotate(up, a);
  a.north_deg = 90.0;
  annotate(east, a);
  const auto red = [](Rgb8 c) { return c.r > 150 && c.g < 60 && c.b < 60; };
  EXPECT_GT(count(up, 700, 0, 800, 100, red), 30);
  EXPECT_NE(up.rgba, east.rgba);
  // North up: the red half lies above the disc's centre; north east: right of it.
  const auto centre = [&](const ImageRgba& img, bool horizontal) {
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < 100; ++y) {
      for (int x = 700; x < 800; ++x) {
        if (red(at(img, x, y))) sum += horizontal ? x : y, ++n;
      }
    }
    return sum / n;
  };
  EXPECT_LT(centre(up, false), centre(east, false));
  EXPECT_GT(centre(east, true), centre(up, true));
}

TEST(Annotate, TinyAndHugeImagesDoNotThrow) {
  ImageRgba tiny = uniform(64, 48);
  EXPECT_NO_THROW(annotate(tiny, everything()));
  ImageRgba huge = uniform(4000, 3000);
  EXPECT_NO_THROW(annotate(huge, everything()));
  EXPECT_EQ(huge.rgba.size(), 4000U * 3000U * 4U);
}

TEST(Annotate, RejectsEmptyOrInconsistentImages) {
  ImageRgba empty;
  EXPECT_THROW(annotate(empty, everything()), RenderError);
  EXPECT_THROW(annotate(empty, Annotations{}), RenderError);
  ImageRgba short_buffer = uniform(10, 10);
  short_buffer.rgba.pop_back();
  EXPECT_THROW(annotate(short_buffer, everything()), RenderError);
  ImageRgba negative{-4, 4, {}};
  EXPECT_THROW(annotate(negative, everything()), RenderError);
}

TEST(Annotate, RejectsNonFiniteParameters) {
  ImageRgba image = uniform(100, 100);
  const ImageRgba before = image;
  constexpr double kInf = std::numeric_limits<double>::infinity();
  Annotations bar;
  bar.color_bar = Annotations::ColorBar{ColorMap::kJet, 0.0, kInf, ""};
  EXPECT_THROW(annotate(image, bar), RenderError);
  Annotations scale;
  scale.metres_per_pixel = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(annotate(image, scale), RenderError);
  Annotations north;
  north.north_deg = kInf;
  EXPECT_THROW(annotate(image, north), RenderError);
  EXPECT_EQ(image.rgba, before.rgba) << "a rejected call must not draw";
}

TEST(Annotate, FlatColorBarRangeDrawsMiddleColour) {
  ImageRgba image = uniform(400, 300);
  Annotations a;
  a.color_bar = Annotations::ColorBar{ColorMap::kJet, 5.0, 5.0, "constant"};
  annotate(image, a);
  const Rgb8 mid = to8(colormap(ColorMap::kJet, 0.5));
  EXPECT_GT(count(image, 300, 0, 400, 300, [&](Rgb8 c) { return close(c, mid, 2); }), 500);
}

// Random bytes, translucent pixels included: anything the overlays leave alone must come back
// byte-identical through the premultiplied ARGB conversion.
ImageRgba noise(int width, int height) {
  ImageRgba image{width, height, std::vector<std::uint8_t>(4U * width * height)};
  std::mt19937 rng(42);
  std::uniform_int_distribution<int> byte(0, 255);
  for (std::uint8_t& v : image.rgba) v = static_cast<std::uint8_t>(byte(rng));
  return image;
}

TEST(Annotate, EmptyAnnotationsLeaveImageByteIdentical) {
  const ImageRgba before = noise(123, 77);
  ImageRgba image = before;
  annotate(image, Annotations{});
  EXPECT_EQ(image.rgba, before.rgba);
  Annotations negative_scale;
  negative_scale.metres_per_pixel = -1.0;  // only > 0 draws a scale bar
  annotate(image, negative_scale);
  EXPECT_EQ(image.rgba, before.rgba);
}

TEST(Annotate, UntouchedPixelsSurviveTheRoundTrip) {
  const ImageRgba before = noise(400, 300);
  ImageRgba image = before;
  Annotations a;
  a.title = "title";
  annotate(image, a);
  EXPECT_NE(image.rgba, before.rgba);
  EXPECT_TRUE(regionUnchanged(image, before, 0, 100, 400, 300));
}

TEST(Annotate, OpaqueDrawingStaysOpaque) {
  ImageRgba image = uniform(800, 600);
  annotate(image, everything());
  for (std::size_t i = 3; i < image.rgba.size(); i += 4) ASSERT_EQ(image.rgba[i], 255) << i;
}

TEST(ScaleBar, NiceLengths) {
  EXPECT_DOUBLE_EQ(niceLength(80.0), 50.0);
  EXPECT_DOUBLE_EQ(niceLength(50.0), 50.0);
  EXPECT_DOUBLE_EQ(niceLength(49.0), 20.0);
  EXPECT_DOUBLE_EQ(niceLength(100.0), 100.0);
  EXPECT_DOUBLE_EQ(niceLength(1000.0), 1000.0);
  EXPECT_DOUBLE_EQ(niceLength(3500.0), 2000.0);
  EXPECT_DOUBLE_EQ(niceLength(1.9), 1.0);
  EXPECT_NEAR(niceLength(0.3), 0.2, 1e-12);
  EXPECT_THROW(niceLength(0.0), RenderError);
  EXPECT_THROW(niceLength(std::numeric_limits<double>::quiet_NaN()), RenderError);
}

TEST(ScaleBar, DistanceLabels) {
  EXPECT_EQ(formatDistance(50.0), "50 m");
  EXPECT_EQ(formatDistance(2000.0), "2 km");
  EXPECT_EQ(formatDistance(500.0), "500 m");
  EXPECT_EQ(formatDistance(1.0), "1 m");
  EXPECT_EQ(formatDistance(niceLength(0.3)), "20 cm");
  EXPECT_EQ(formatDistance(0.005), "5 mm");
  EXPECT_EQ(formatDistance(20000.0), "20 km");
}

// A map-like backdrop with dark, bright and saturated areas, so readability can be judged.
ImageRgba demoBackground(int width, int height) {
  ImageRgba image{width, height, {}};
  image.rgba.reserve(4U * width * height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double u = static_cast<double>(x) / width, v = static_cast<double>(y) / height;
      const double t = 0.5 + 0.5 * std::sin(6.0 * u + 2.0 * std::cos(5.0 * v)) * std::cos(4.0 * v);
      const Rgb c = colormap(ColorMap::kJet, t);
      const double shade = u < 0.5 ? 0.35 : 0.9;  // left half dark, right half bright
      for (float ch : {c.r, c.g, c.b}) {
        image.rgba.push_back(
            static_cast<std::uint8_t>(std::lround(255.0 * shade * static_cast<double>(ch))));
      }
      image.rgba.push_back(255);
    }
  }
  return image;
}

void writePng(const ImageRgba& image, const std::string& path) {
  cv::Mat bgra(image.height, image.width, CV_8UC4);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      bgra.at<cv::Vec4b>(y, x) = cv::Vec4b(p[2], p[1], p[0], p[3]);
    }
  }
  ASSERT_TRUE(cv::imwrite(path, bgra)) << path;
}

// Renders demos at three sizes; GVIO_ANNOTATE_DEMO_DIR=<dir> keeps them for a visual check.
TEST(Annotate, DemoImages) {
  const char* dir = std::getenv("GVIO_ANNOTATE_DEMO_DIR");
  for (const auto& [w, h] : {std::pair{800, 600}, std::pair{320, 240}, std::pair{3840, 2160}}) {
    ImageRgba image = demoBackground(w, h);
    ASSERT_NO_THROW(annotate(image, everything()));
    if (dir != nullptr) {
      writePng(image, std::string(dir) + "/annotate_demo_" + std::to_string(w) + ".png");
    }
  }
}

}  // namespace
}  // namespace gvio::render
