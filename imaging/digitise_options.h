// Options of digitise (one struct, strict JSON). Every threshold with a physical meaning is in metres or square
// metres and converted through the image's pixel scale, so one configuration serves images of any resolution
// showing the same kind of ice. Defaults were chosen by measurement on synthetic helicopter images at the SAMS
// camera's 1.1794 m/px (seeds 1-8, also with 0.3 m gaps, noise 12, a 40% illumination ramp; see README.md),
// not on one image. For close-range photographs (cm per pixel) imaging/settings/close_range.json holds a set
// chosen by cross-validation on the 12 hand-labelled passerotti images at 0.05 m/px (README.md, issue #3).
#pragma once
#include <string>
#include <vector>

#include "imaging/georeference.h"
#include "pipeline/options.h"

namespace floesim::imaging {

struct DigitiseOptions {
  double max_pixels = 50e6;              // larger images are refused before decoding: digitise needs about
                                         // 80 bytes per pixel (measured peak 230 MB for 2.8 megapixels), ~4 GB
  double smoothing_m = 0.0;              // Gaussian sigma of the pre-smoothing (sensor noise, surface texture);
                                         // 0 = none (the helicopter scale: a pixel is already ~1 m)
  std::string illumination = "two_class";  // how the local water and ice brightness are estimated:
                                           // "two_class": masked Gaussian means of the two classes of a global
                                           // split (smooth illumination, one ice brightness); "local_otsu": Otsu
                                           // in blocks of local_block_m (also darker far fields and grey floes)
  double illumination_scale_m = 150.0;   // Gaussian sigma of the smooth water and ice brightness estimates
  double local_block_m = 4.0;            // block size of the "local_otsu" levels (must hold ice and water)
  double threshold_fraction = 0.45;      // ice where (I - water) / (ice - water) exceeds this (local levels);
                                         // below 0.5 because blur darkens corners and small floes
  double core_fraction = 0.75;           // floe cores (splitting seeds): smoothed brightness above this fraction
                                         // of their ice piece's bright level; 0 = the whole ice piece is core
  double min_contrast = 30.0;            // ice and water must differ by this many grey levels, else one class
                                         // ("local_otsu": blocks below it have no say in the local levels)
  bool allow_one_class = false;          // an image of one class (all ice or no ice): refused unless this is set
  double crack_width_m = 0.0;            // dark lines (cracks, shadows between touching floes) up to this wide
                                         // are cut from the ice (black top-hat); 0 = off
  double crack_depth = 0.3;              // ... where they are this much darker than their surroundings, as a
                                         // fraction of the local ice-water contrast
  double max_hole_area_m2 = 2000.0;      // water enclosed by one ice region up to this area is a melt pond (ice)
  double opening_radius_m = 0.5;         // morphological opening: removes bridges and specks thinner than ~2x;
                                         // rounds to no opening at 1.18 m/px (it cut the corners of 5 m floes)
  double brash_cutoff_m2 = 10.0;         // connected ice pieces smaller than this are brash and dropped
  double marker_dynamic_m = 1.5;         // a bump of the distance map must rise this much to seed its own floe
  double min_marker_separation_m = 3.0;  // seeds closer than this (within one ice piece) are one floe
  double neck_ratio = 0.85;              // two pieces whose neck half-width reaches this fraction of the smaller
                                         // one's inscribed radius are one floe with a dent (see segment.h)
  double min_floe_area_m2 = 10.0;        // split pieces smaller than this rejoin their neighbour; lone ones dropped
  double edge_band_m = 0.1;              // outline refinement: within this of its outline a floe keeps ...
  double edge_fraction = 0.0;            // ... only pixels brighter than this fraction of its median
                                         // normalised brightness (its edge at its own half level); 0 = off
  double simplify_tolerance_m = 0.5;     // Douglas-Peucker tolerance of the outlines
  double thickness_m = 1.0;              // written to every floe (SAMS table: h = 1 m)
  bool convex_parts = false;             // also write convex_parts.geojson: each floe split into convex pieces
  std::vector<double> georeference;      // [latitude_deg, longitude_deg, heading_deg] of the image centre (WGS 84)
                                         // and its up axis (clockwise from true north): also floes_wgs84.geojson
  int size_bins_per_decade = 5;          // floe size distribution table: log-spaced bins of equivalent diameter
  double fit_min_diameter_m = 0.0;       // power-law fit uses floes with D >= this (0: chosen from the data by
                                         // the Kolmogorov-Smirnov criterion of Clauset et al. 2009)

  template <class V>
  void visit(V& v) {
    v.field("max_pixels", max_pixels, "px", "largest image accepted (checked from the file header)", positive());
    v.field("smoothing_m", smoothing_m, "m", "Gaussian sigma of the pre-smoothing (noise, texture); 0 = none",
            non_negative());
    v.field("illumination", illumination, "-",
            "local water/ice brightness: two_class (smooth masked class means) or local_otsu (Otsu per block)",
            one_of({"two_class", "local_otsu"}));
    v.field("illumination_scale_m", illumination_scale_m, "m",
            "smoothing scale of the local water and ice brightness (illumination correction)", positive());
    v.field("local_block_m", local_block_m, "m", "block size of the local_otsu brightness levels", positive());
    v.field("threshold_fraction", threshold_fraction, "-",
            "ice/water threshold between the local water (0) and ice (1) brightness", in_range(0.05, 0.95));
    v.field("core_fraction", core_fraction, "-",
            "floe cores for splitting: smoothed brightness above this fraction of their ice piece's bright level "
            "(0: the whole piece)",
            in_range(0, 1.5));
    v.field("min_contrast", min_contrast, "grey", "least ice-water contrast; below it the image is one class",
            in_range(1, 255));
    v.field("allow_one_class", allow_one_class, "-",
            "accept an image of one class (no water: each connected area one floe; no ice: no floes) with a warning; "
            "false: such an image is an error");
    v.field("crack_width_m", crack_width_m, "m",
            "widest dark line between floes cut from the ice (black top-hat); 0 = off", non_negative());
    v.field("crack_depth", crack_depth, "-",
            "least depth of a cut dark line, as a fraction of the local ice-water contrast", in_range(0.01, 10));
    v.field("max_hole_area_m2", max_hole_area_m2, "m^2", "largest enclosed water filled as a melt pond",
            non_negative());
    v.field("opening_radius_m", opening_radius_m, "m", "radius of the morphological opening", non_negative());
    v.field("brash_cutoff_m2", brash_cutoff_m2, "m^2", "ice pieces below this area are brash", non_negative());
    v.field("marker_dynamic_m", marker_dynamic_m, "m", "least rise of a distance-map maximum to seed a floe (h-maxima)",
            positive());
    v.field("min_marker_separation_m", min_marker_separation_m, "m",
            "splitting seeds closer than this within one ice piece are one floe", non_negative());
    v.field("neck_ratio", neck_ratio, "-",
            "two pieces are one floe if their neck's half-width reaches this fraction of the smaller one's "
            "inscribed radius",
            in_range(0, 10));
    v.field("min_floe_area_m2", min_floe_area_m2, "m^2", "smallest floe kept after splitting", non_negative());
    v.field("edge_band_m", edge_band_m, "m", "width of the outline band refined at the floe's own level",
            non_negative());
    v.field("edge_fraction", edge_fraction, "-",
            "outline pixels darker than this fraction of their floe's median brightness are water (0 = off)",
            in_range(0, 1));
    v.field("simplify_tolerance_m", simplify_tolerance_m, "m", "outline simplification tolerance", non_negative());
    v.field("thickness_m", thickness_m, "m", "ice thickness written to every floe", positive());
    v.field("convex_parts", convex_parts, "-",
            "also write convex_parts.geojson (each floe as a MultiPolygon of convex pieces that tile it)");
    v.field("georeference", georeference, "deg",
            "[latitude, longitude, heading] of the image centre (WGS 84) and of its up axis (clockwise from true "
            "north); also writes floes_wgs84.geojson for a GIS; [] = none",
            Check<std::vector<double>>([](const std::vector<double>& g) {
              return g.empty() ? std::string() : georeference_problem(g);
            }));
    v.field("size_bins_per_decade", size_bins_per_decade, "-", "size distribution bins per decade of diameter",
            int_in_range(1, 50));
    v.field("fit_min_diameter_m", fit_min_diameter_m, "m", "lower bound of the power-law fit (0: KS-minimising choice, Clauset et al. 2009)",
            non_negative());
  }
};

}  // namespace floesim::imaging
