// Reading: one evidence point from stereo, in quasi-cylindrical coordinates about the PTU centre.
#pragma once

namespace boticelli::evidence {

// Thesis §4.5.2 (quasi-cylindrical coordinates; the thesis uses dm, we use SI).
struct Reading {
  float alpha_rad = 0.0F;  // pan angle of the point about the PTU centre, in [0, 2π)
  float h_m = 0.0F;        // height of the point relative to the PTU centre [m]
  float r_m = 0.0F;        // distance from the PTU centre to the point [m]
  float m = 0.0F;          // evidence in [0, 1] (Eq 3.8)
};

}  // namespace boticelli::evidence
