#pragma once
// The zone of comfort of stereo viewing (Shibata, Kim, Hoffman & Banks, "The zone of comfort:
// Predicting visual discomfort with stereo displays", Journal of Vision 11(8):11, 2011): how far the
// eyes' focus may be from where they converge before viewing becomes uncomfortable. Their fit, in
// diopters (D_v vergence, D_f focal distance), bounds the comfortable vergence for a focal distance:
//   far boundary  D_v = 1.035 D_f - 0.626,   near boundary  D_v = 1.129 D_f + 0.442.
// `nelf simulate --sweep` draws it on its heatmap, as Lanman & Luebke's Fig. 11 does.

namespace nelf {

struct AccommodationRange {
  double farthest_diopters = 0;  // the far end (0 = infinity; never below)
  double nearest_diopters = 0;   // the near end
  bool contains(double diopters) const { return diopters >= farthest_diopters && diopters <= nearest_diopters; }
};

// The focal distances that are comfortable while the eyes converge at `vergence_diopters`: the two
// boundaries solved for D_f. Throws std::invalid_argument for a negative or non-finite vergence.
AccommodationRange comfortable_accommodation(double vergence_diopters);

}  // namespace nelf
