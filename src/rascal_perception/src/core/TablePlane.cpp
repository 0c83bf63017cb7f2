#include "rascal_perception/TablePlane.hpp"

#include <pcl/console/print.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_plane.h>

namespace rascal_perception {

namespace {
/// PCL prints an error line for every degenerate (collinear) RANSAC sample, which is routine on a
/// pixel grid of quantised depth; keep PCL quiet while fitting and restore its level afterwards.
class QuietPcl {
 public:
  QuietPcl() : saved_(pcl::console::getVerbosityLevel()) {
    pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  }
  ~QuietPcl() { pcl::console::setVerbosityLevel(saved_); }
  QuietPcl(const QuietPcl&) = delete;
  QuietPcl& operator=(const QuietPcl&) = delete;

 private:
  pcl::console::VERBOSITY_LEVEL saved_;
};
}  // namespace

PlaneFit TablePlane::fit(const std::vector<Eigen::Vector3f>& points, double tolerance, int min_inliers) {
  PlaneFit out;
  if (static_cast<int>(points.size()) < std::max(3, min_inliers)) return out;
  const QuietPcl quiet;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(points.size());
  for (const Eigen::Vector3f& p : points) cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  // random = false: the model's sampler has a fixed seed, so fits are repeatable
  pcl::SampleConsensusModelPlane<pcl::PointXYZ>::Ptr model(
      new pcl::SampleConsensusModelPlane<pcl::PointXYZ>(cloud, false));
  pcl::RandomSampleConsensus<pcl::PointXYZ> ransac(model, tolerance);
  ransac.setMaxIterations(200);
  if (!ransac.computeModel()) return out;
  pcl::Indices inliers;
  ransac.getInliers(inliers);
  if (static_cast<int>(inliers.size()) < min_inliers) return out;
  Eigen::VectorXf coeffs, refined;
  ransac.getModelCoefficients(coeffs);
  model->optimizeModelCoefficients(inliers, coeffs, refined);
  Eigen::Vector4d plane = refined.cast<double>();
  const double norm = plane.head<3>().norm();
  if (norm < 1e-9) return out;
  plane /= norm;
  if (plane.z() < 0) plane = -plane;
  out.ok = true;
  out.plane = plane;
  out.inliers = static_cast<int>(inliers.size());
  return out;
}

}  // namespace rascal_perception
