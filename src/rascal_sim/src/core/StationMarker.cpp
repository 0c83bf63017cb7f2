#include "rascal_sim/StationMarker.hpp"

#include <Eigen/Geometry>
#include <opencv2/aruco.hpp>

namespace rascal_sim {

namespace {
constexpr int kCells = 6;           // black border + 4 bits + black border
constexpr int kDrawn = kCells + 2;  // with the quiet margin
const Eigen::Vector3d kBlack{0.04, 0.04, 0.04}, kWhite{0.95, 0.95, 0.95};  // as the scale bar

/// [m] base_link point of the marker's station-frame offset `local` from its centre.
Eigen::Vector2d place(const StationMarker& m, const Eigen::Vector2d& local) {
  return m.centre + Eigen::Rotation2Dd(m.yaw) * local;
}
}  // namespace

std::array<Eigen::Vector2d, 4> StationMarker::corners() const {
  const double h = kSide / 2;
  return {place(*this, {-h, h}), place(*this, {h, h}), place(*this, {h, -h}), place(*this, {-h, -h})};
}

void StationMarker::draw(Mesh& mesh) const {
  cv::Mat bits;  // one pixel a cell, 0 = black
  cv::aruco::getPredefinedDictionary(cv::aruco::DICT_4X4_50)->drawMarker(id, kCells, bits, 1);
  const double cell = kSide / kCells;
  // grid point (column c, row r) of the drawn square, row 0 at the station's +y side; every cell
  // takes its corners from here, so neighbours share them exactly and no gap shows between them
  auto at = [&](int c, int r) {
    const Eigen::Vector2d p = place(*this, {(c - kDrawn / 2.0) * cell, (kDrawn / 2.0 - r) * cell});
    return Eigen::Vector3d(p.x(), p.y(), kZ);
  };
  for (int r = 0; r < kDrawn; ++r) {
    for (int c = 0; c < kDrawn; ++c) {
      const bool margin = r == 0 || c == 0 || r == kDrawn - 1 || c == kDrawn - 1;
      const bool black = !margin && bits.at<uint8_t>(r - 1, c - 1) == 0;
      // counter-clockwise seen from above: the fixtures cull back faces
      mesh.addQuad(at(c, r + 1), at(c + 1, r + 1), at(c + 1, r), at(c, r), black ? kBlack : kWhite);
    }
  }
}

}  // namespace rascal_sim
