// The run for ParaView: a VTK series beside results.h5 (simulate.paraview). DIR/results.pvd lists one PolyData file
// per results frame (DIR/frame_00000.vtp, ...), at the frame's time: every floe as a prism of its thickness (top,
// bottom, a quad per side) and the hull, in world coordinates (x right, y up, z up from the water), with cell data
// body_id (0 the vessel), kind (0 a floe, 1 a level-ice tile, 2 a piece, 3 the hull), in_contact and centre_m (the
// body's centre of mass, as FrameReplay gives it), and field data TimeValue and surge_ice_load_n (the step's surge
// ice load, body axes). ParaView opens the .pvd with the floes, pieces and hull moving; "Plot Data Over Time" plots
// the load. Binary (raw appended, little endian).
#pragma once
#include <filesystem>
#include <string>

#include "pipeline/results_io.h"

namespace floesim {

// Writes the series into `dir` (replacing it) as a whole: the files go into a temporary folder renamed at the end.
// Needs r's states, geometry and the series time_s and ice_load. Returns the bytes written.
size_t write_vtk_series(const Results& r, const std::filesystem::path& dir, const std::string& source);

}  // namespace floesim
