// Prints the unit normal of the plane through the points given on the command line (x y z each),
// the eigenvector of their scatter matrix with the smallest eigenvalue, as the book's plane fit.
#include <Eigen/Eigen>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
  const int count = (argc - 1) / 3;
  Eigen::MatrixXd points(3, count);
  for (int i = 0; i < count; ++i)
    for (int j = 0; j < 3; ++j) points(j, i) = std::atof(argv[1 + 3 * i + j]);
  const Eigen::Vector3d centroid = points.rowwise().mean();
  const Eigen::MatrixXd centred = points.colwise() - centroid;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(centred * centred.transpose());
  Eigen::Vector3d normal = solver.eigenvectors().col(0);  // eigenvalues ascend
  if (normal.z() < 0) normal = -normal;
  std::printf("%.6f %.6f %.6f\n", normal.x(), normal.y(), normal.z());
  return 0;
}
