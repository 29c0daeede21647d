#include "render/colormap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "odometry/error.hpp"
#include "render/render_error.hpp"

namespace gvio::render {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void expectNear(Rgb actual, Rgb expected, double tol) {
  EXPECT_NEAR(actual.r, expected.r, tol);
  EXPECT_NEAR(actual.g, expected.g, tol);
  EXPECT_NEAR(actual.b, expected.b, tol);
}

double luminance(Rgb c) {
  return 0.2126 * static_cast<double>(c.r) + 0.7152 * static_cast<double>(c.g) +
         0.0722 * static_cast<double>(c.b);
}

TEST(Colormap, ViridisEndpointsMatchMatplotlib) {
  expectNear(colormap(ColorMap::kViridis, 0.0), {0.267F, 0.005F, 0.329F}, 0.01);
  expectNear(colormap(ColorMap::kViridis, 1.0), {0.993F, 0.906F, 0.144F}, 0.01);
  // matplotlib's entry 128 of 256 (t = 0.502).
  expectNear(colormap(ColorMap::kViridis, 128.0 / 255.0), {0.128F, 0.567F, 0.551F}, 0.01);
}

TEST(Colormap, ViridisLuminanceStrictlyIncreases) {
  double previous = -1.0;
  for (int i = 0; i < 100; ++i) {
    const double l = luminance(colormap(ColorMap::kViridis, i / 99.0));
    EXPECT_GT(l, previous) << "at sample " << i;
    previous = l;
  }
}

TEST(Colormap, JetRunsBlueGreenRed) {
  const Rgb lo = colormap(ColorMap::kJet, 0.0), mid = colormap(ColorMap::kJet, 0.5);
  const Rgb hi = colormap(ColorMap::kJet, 1.0);
  EXPECT_GT(lo.b, 0.4F);
  EXPECT_LT(lo.r + lo.g, 0.1F);
  EXPECT_GT(mid.g, 0.9F);
  EXPECT_LT(std::max(mid.r, mid.b), 0.6F);
  EXPECT_GT(hi.r, 0.4F);
  EXPECT_LT(hi.g + hi.b, 0.1F);
  // The classic breakpoints: pure blue at 1/8, cyan at 3/8, yellow at 5/8, pure red at 7/8.
  expectNear(colormap(ColorMap::kJet, 0.125), {0.0F, 0.0F, 1.0F}, 1e-6);
  expectNear(colormap(ColorMap::kJet, 0.375), {0.0F, 1.0F, 1.0F}, 1e-6);
  expectNear(colormap(ColorMap::kJet, 0.625), {1.0F, 1.0F, 0.0F}, 1e-6);
  expectNear(colormap(ColorMap::kJet, 0.875), {1.0F, 0.0F, 0.0F}, 1e-6);
}

TEST(Colormap, GrayIsTheValue) {
  expectNear(colormap(ColorMap::kGray, 0.0), {0.0F, 0.0F, 0.0F}, 1e-6);
  expectNear(colormap(ColorMap::kGray, 0.3), {0.3F, 0.3F, 0.3F}, 1e-6);
  expectNear(colormap(ColorMap::kGray, 1.0), {1.0F, 1.0F, 1.0F}, 1e-6);
}

TEST(Colormap, ClampsOutOfRangeAndGreysNaN) {
  for (ColorMap map : {ColorMap::kViridis, ColorMap::kJet, ColorMap::kGray}) {
    expectNear(colormap(map, -3.0), colormap(map, 0.0), 0.0);
    expectNear(colormap(map, 7.0), colormap(map, 1.0), 0.0);
    expectNear(colormap(map, -std::numeric_limits<double>::infinity()), colormap(map, 0.0), 0.0);
    expectNear(colormap(map, std::numeric_limits<double>::infinity()), colormap(map, 1.0), 0.0);
    expectNear(colormap(map, kNaN), {0.5F, 0.5F, 0.5F}, 0.0);
  }
}

TEST(Colormap, ParsesNamesAndRejectsOthers) {
  EXPECT_EQ(parseColorMap("viridis"), ColorMap::kViridis);
  EXPECT_EQ(parseColorMap("jet"), ColorMap::kJet);
  EXPECT_EQ(parseColorMap("gray"), ColorMap::kGray);
  for (const char* bad : {"", "Viridis", "magma", "jet ", "grey"}) {
    EXPECT_THROW(parseColorMap(bad), RenderError) << bad;
  }
  try {
    parseColorMap("magma");
    FAIL();
  } catch (const InvalidInput& e) {  // RenderError is the user's input being wrong (exit 2)
    EXPECT_NE(std::string(e.what()).find("magma"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("viridis"), std::string::npos);
  }
}

TEST(Normalise, MapsLinearlyAndClamps) {
  EXPECT_DOUBLE_EQ(normalise(10.0, 10.0, 20.0), 0.0);
  EXPECT_DOUBLE_EQ(normalise(15.0, 10.0, 20.0), 0.5);
  EXPECT_DOUBLE_EQ(normalise(20.0, 10.0, 20.0), 1.0);
  EXPECT_DOUBLE_EQ(normalise(12.5, 10.0, 20.0), 0.25);
  EXPECT_DOUBLE_EQ(normalise(-100.0, 10.0, 20.0), 0.0);
  EXPECT_DOUBLE_EQ(normalise(100.0, 10.0, 20.0), 1.0);
}

TEST(Normalise, DegenerateRangeGivesMiddle) {
  EXPECT_DOUBLE_EQ(normalise(3.0, 5.0, 5.0), 0.5);
  EXPECT_DOUBLE_EQ(normalise(3.0, 5.0, 1.0), 0.5);
  EXPECT_DOUBLE_EQ(normalise(3.0, kNaN, 1.0), 0.5);
}

TEST(Normalise, NaNValueStaysNaNAndColoursGrey) {
  EXPECT_TRUE(std::isnan(normalise(kNaN, 0.0, 1.0)));
  expectNear(colormap(ColorMap::kViridis, normalise(kNaN, 0.0, 1.0)), {0.5F, 0.5F, 0.5F}, 0.0);
}

}  // namespace
}  // namespace gvio::render
