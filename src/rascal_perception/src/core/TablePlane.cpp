#include "rascal_perception/TablePlane.hpp"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/sample_consensus/ransac.h>
#include <pcl/sample_consensus/sac_model_plane.h>

namespace rascal_perception {

PlaneFit TablePlane::fit(const std::vector<Eigen::Vector3f>& points, double tolerance, int min_inliers) {
  PlaneFit out;
  if (static_cast<int>(points.size()) < std::max(3, min_inliers)) return out;
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
