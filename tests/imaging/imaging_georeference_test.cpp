// A georeferenced image's floes in WGS 84 (issue #37, part 6): the map from the image's metres to latitude and
// longitude against a published geodesic, the heading's turn, and digitise's floes_wgs84.geojson and CRS members.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "imaging/digitise.h"
#include "imaging/georeference.h"
#include "pipeline/floes_io.h"
#include "test_util.h"

namespace floesim::imaging {
namespace {

double dms(double d, double m, double s) { return (std::abs(d) + m / 60 + s / 3600) * (d < 0 ? -1 : 1); }

// Metres between two nearby points (degrees): the ellipsoid's meridian and prime-vertical radii at their mean
// latitude, good to millimetres over the metres compared here.
double metres_apart(double lat1, double lon1, double lat2, double lon2) {
  const double a = 6378137.0, f = 1 / 298.257223563, e2 = f * (2 - f), phi = (lat1 + lat2) / 2 * M_PI / 180;
  const double w = 1 - e2 * std::sin(phi) * std::sin(phi);
  const double m = a * (1 - e2) / std::pow(w, 1.5), n = a / std::sqrt(w);
  return std::hypot((lat2 - lat1) * M_PI / 180 * m, (lon2 - lon1) * M_PI / 180 * n * std::cos(phi));
}

// Vincenty's (1975) worked example, as Geoscience Australia publishes it: from Flinders Peak
// (37°57'03.72030" S, 144°25'29.52440" E) 54,972.271 m at azimuth 306°52'05.37" lies Buninyong
// (37°39'10.15610" S, 143°55'35.38390" E). An image centred on Flinders Peak with its up axis north puts a corner
// there at that distance and azimuth: it must map to Buninyong within 1 m.
TEST(Georeference, AFloeCornerIsAtItsPublishedLatitudeAndLongitude) {
  const GeoReference g{dms(-37, 57, 3.72030), dms(144, 25, 29.52440), 0.0};
  const double s = 54972.271, az = dms(306, 52, 5.37) * M_PI / 180;
  const double w = 120000, h = 120000;  // the image 120 km square: its centre at (60 km, 60 km)
  const auto ll = image_to_wgs84(g, w, h, w / 2 + s * std::sin(az), h / 2 + s * std::cos(az));
  EXPECT_LT(metres_apart(ll[1], ll[0], dms(-37, 39, 10.15610), dms(143, 55, 35.38390)), 1.0)
      << ll[1] << ", " << ll[0];
  // The centre is the centre.
  const auto c = image_to_wgs84(g, w, h, w / 2, h / 2);
  EXPECT_LT(metres_apart(c[1], c[0], g.latitude_deg, g.longitude_deg), 1e-3);
}

// Heading 90°: the image's up axis points east, its right axis south. A point 500 m up lies where, unturned, a
// point 500 m right lies; a point 500 m right lies 500 m south of the centre (a meridian's length: 78°N).
TEST(Georeference, TheHeadingTurnsTheImageClockwiseFromNorth) {
  const GeoReference north{78.2, 15.6, 0.0}, east{78.2, 15.6, 90.0};
  const auto up_turned = image_to_wgs84(east, 2000, 2000, 1000, 1500);
  const auto right = image_to_wgs84(north, 2000, 2000, 1500, 1000);
  EXPECT_LT(metres_apart(up_turned[1], up_turned[0], right[1], right[0]), 0.01);
  const auto right_turned = image_to_wgs84(east, 2000, 2000, 1500, 1000);
  EXPECT_NEAR(right_turned[0], 15.6, 1e-9) << "due south: the same longitude";
  EXPECT_NEAR(metres_apart(right_turned[1], right_turned[0], 78.2, 15.6), 500.0, 0.01);
  EXPECT_LT(right_turned[1], 78.2);
}

// A request to digitise `img` (written into `d`) at 1 m/px with digitise.georeference = `georeference`.
DigitiseRequest georeferenced_request(const test::ScratchDir& d, const cv::Mat& img, const Json& georeference) {
  cv::imwrite((d.path / "image.png").string(), img);
  DigitiseRequest req;
  req.image = d.path / "image.png";
  req.metres_per_pixel = 1.0;
  req.out_dir = d.path / "out";
  req.config = {{"georeference", georeference}};
  return req;
}

TEST(Georeference, DigitiseWritesTheFloesInWgs84AndEveryFileDeclaresItsCrs) {
  cv::Mat img(120, 160, CV_8U);
  cv::randu(img, 30, 60);
  cv::rectangle(img, cv::Rect(20, 20, 50, 40), cv::Scalar(220), cv::FILLED);
  test::ScratchDir d;
  const DigitiseRequest req = georeferenced_request(d, img, {78.2, 15.6, 30.0});
  const DigitiseResult res = run_digitise(req);
  ASSERT_EQ(res.floes.floes.size(), 1u);
  const Json local = load_json_file(req.out_dir / "floes.geojson");
  EXPECT_EQ(local["crs"]["properties"]["name"], kLocalMetresCrs);
  const Json geo = load_json_file(req.out_dir / "floes_wgs84.geojson");
  EXPECT_EQ(geo["crs"]["properties"]["name"], "urn:ogc:def:crs:OGC:1.3:CRS84");
  const Json& ring = geo["features"][0]["geometry"]["coordinates"][0];
  const Json& ring_m = local["features"][0]["geometry"]["coordinates"][0];
  ASSERT_EQ(ring.size(), ring_m.size());
  // Two vertices as far apart on the map as in the image (a map of 160 m keeps lengths to far below a centimetre).
  const double metres = std::hypot(ring_m[0][0].get<double>() - ring_m[2][0].get<double>(),
                                   ring_m[0][1].get<double>() - ring_m[2][1].get<double>());
  EXPECT_NEAR(metres_apart(ring[0][1], ring[0][0], ring[2][1], ring[2][0]), metres, 0.01);
  // The map layer is not a floe field in metres: the simulation's reader refuses it, saying which file to give.
  try {
    read_floes(req.out_dir / "floes_wgs84.geojson");
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("floes.geojson"), std::string::npos) << e.what();
  }
}

std::string text_of(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A raster's world file (A, D, B, E, C, F): where the image point at pixel (column, row) lies.
std::array<double, 2> world_point(const std::filesystem::path& pgw, double col, double row) {
  std::ifstream in(pgw);
  double a = 0, d = 0, b = 0, e = 0, c = 0, f = 0;
  EXPECT_TRUE(static_cast<bool>(in >> a >> d >> b >> e >> c >> f)) << pgw;
  return {a * col + b * row + c, d * col + e * row + f};
}

// The rasters' world files place their corners by hand geometry. A 160 x 120 px image at 1 m/px: without a
// georeference its bottom-left corner (pixel -0.5, 119.5) is at the image frame's origin and its top-right at
// (160, 120) m. With heading 90 deg the image's up axis points east and its right axis south: its top-left corner,
// 80 m left and 60 m up from the centre, is 60 m east and 80 m north of it in the azimuthal equidistant map the
// .prj names about the centre's latitude and longitude.
TEST(Georeference, TheRastersWorldFilesPutTheirCornersWhereTheFloesAre) {
  cv::Mat img(120, 160, CV_8U);
  cv::randu(img, 30, 60);
  cv::rectangle(img, cv::Rect(20, 20, 50, 40), cv::Scalar(220), cv::FILLED);
  {
    test::ScratchDir d;
    DigitiseRequest req = georeferenced_request(d, img, Json());
    req.config = Json::object();
    run_digitise(req);
    for (const char* name : {"labels", "overlay"}) {
      const std::filesystem::path out = req.out_dir / name;
      const std::string pgw = out.string() + ".pgw";
      const auto bl = world_point(pgw, -0.5, 119.5), tr = world_point(pgw, 159.5, -0.5);
      EXPECT_NEAR(bl[0], 0, 1e-12);
      EXPECT_NEAR(bl[1], 0, 1e-12);
      EXPECT_NEAR(tr[0], 160, 1e-12);
      EXPECT_NEAR(tr[1], 120, 1e-12);
      EXPECT_EQ(text_of(out.string() + ".prj"), std::string(kLocalMetresCrs) + "\n");
    }
  }
  test::ScratchDir d;
  const DigitiseRequest req = georeferenced_request(d, img, {78.2, 15.6, 90.0});
  run_digitise(req);
  const std::string pgw = (req.out_dir / "overlay.pgw").string();
  const auto tl = world_point(pgw, -0.5, -0.5), br = world_point(pgw, 159.5, 119.5);
  EXPECT_NEAR(tl[0], 60, 1e-9);
  EXPECT_NEAR(tl[1], 80, 1e-9);
  EXPECT_NEAR(br[0], -60, 1e-9);
  EXPECT_NEAR(br[1], -80, 1e-9);
  const std::string prj = text_of(req.out_dir / "overlay.prj");
  EXPECT_NE(prj.find("PROJECTION[\"Azimuthal_Equidistant\"]"), std::string::npos) << prj;
  EXPECT_NE(prj.find("PARAMETER[\"Latitude_Of_Origin\",78.2]"), std::string::npos) << prj;
  EXPECT_NE(prj.find("PARAMETER[\"Central_Meridian\",15.6]"), std::string::npos) << prj;
}

TEST(Georeference, ALatitudeOffTheEarthIsRefusedNamingTheKey) {
  cv::Mat img(60, 60, CV_8U, cv::Scalar(40));
  cv::rectangle(img, cv::Rect(20, 20, 20, 20), cv::Scalar(220), cv::FILLED);
  test::ScratchDir d;
  const DigitiseRequest req = georeferenced_request(d, img, {95.0, 15.6, 0.0});
  try {
    run_digitise(req);
    ADD_FAILURE() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("georeference"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("latitude"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(req.out_dir / "floes.geojson"));
}

}  // namespace
}  // namespace floesim::imaging
