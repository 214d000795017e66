#include "io/calibration_file.h"

#include <cmath>

#include <opencv2/core/eigen.hpp>

#include "io/atomic_file.h"
#include "io/input_error.h"

namespace everytouch::io {

namespace {

cv::FileNode requireKey(const cv::FileNode& root, const std::string& inputName, const char* key) {
    cv::FileNode node = root[key];
    if (node.empty())
        throw InputError(inputName, key, "missing");
    return node;
}

cv::Size readSize(const cv::FileNode& root, const std::string& inputName, const char* key) {
    const cv::FileNode node = requireKey(root, inputName, key);
    if (!node.isSeq() || node.size() != 2 || !node[0].isInt() || !node[1].isInt())
        throw InputError(inputName, key, "expected [width, height] as two integers");
    const cv::Size size(static_cast<int>(node[0]), static_cast<int>(node[1]));
    if (size.width <= 0 || size.height <= 0)
        throw InputError(inputName, key, "width and height must be positive");
    return size;
}

// Reads an opencv-matrix of `rows` x `cols` doubles; a vector may be stored as a row or a column.
cv::Mat readMatrix(const cv::FileNode& root, const std::string& inputName, const char* key, int rows,
                   int cols) {
    const cv::FileNode node = requireKey(root, inputName, key);
    cv::Mat matrix;
    try {
        node >> matrix;
    } catch (const cv::Exception&) {
        matrix.release();
    }
    if (matrix.empty())
        throw InputError(inputName, key, "expected an opencv-matrix");
    const bool vectorTransposed = (rows == 1 || cols == 1) && matrix.rows == cols && matrix.cols == rows;
    if (!(matrix.rows == rows && matrix.cols == cols) && !vectorTransposed)
        throw InputError(inputName, key,
                         "expected a " + std::to_string(rows) + "x" + std::to_string(cols) +
                             " matrix, found " + std::to_string(matrix.rows) + "x" +
                             std::to_string(matrix.cols));
    if (matrix.channels() != 1)
        throw InputError(inputName, key, "expected a single-channel matrix");
    cv::Mat asDouble;
    matrix.convertTo(asDouble, CV_64F);
    if (!cv::checkRange(asDouble))
        throw InputError(inputName, key, "contains a value that is not a finite number");
    return vectorTransposed ? cv::Mat(asDouble.t()) : asDouble;
}

template <int Rows, int Cols>
Eigen::Matrix<double, Rows, Cols> readEigen(const cv::FileNode& root, const std::string& inputName,
                                            const char* key) {
    Eigen::Matrix<double, Rows, Cols> result;
    cv::cv2eigen(readMatrix(root, inputName, key, Rows, Cols), result);
    return result;
}

template <typename Derived>
cv::Mat toMat(const Eigen::MatrixBase<Derived>& matrix) {
    cv::Mat result;
    cv::eigen2cv(Eigen::Matrix<double, Derived::RowsAtCompileTime, Derived::ColsAtCompileTime>(matrix),
                 result);
    return result;
}

void writeSize(cv::FileStorage& storage, const char* key, const cv::Size& size) {
    storage << key << "[:" << size.width << size.height << "]";
}

}  // namespace

cv::FileStorage openYamlForReading(const std::filesystem::path& path) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        throw InputError(path.string(), "", "no such file");
    cv::FileStorage storage;
    try {
        storage.open(path.string(), cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML);
    } catch (const cv::Exception& e) {
        throw InputError(path.string(), "", "not a valid YAML document (" + e.err + ")");
    }
    if (!storage.isOpened() || !storage.root().isMap())
        throw InputError(path.string(), "", "not a valid YAML document");
    return storage;
}

void checkFormatHeader(const cv::FileNode& root, const std::string& inputName,
                       std::initializer_list<const char*> acceptedFormats, int version) {
    const cv::FileNode format = requireKey(root, inputName, "format");
    bool accepted = false;
    if (format.isString())
        for (const char* name : acceptedFormats)
            accepted = accepted || format.string() == name;
    if (!accepted)
        throw InputError(inputName, "format", std::string("expected \"") + *acceptedFormats.begin() + "\"");
    const cv::FileNode versionNode = requireKey(root, inputName, "version");
    if (!versionNode.isInt() || static_cast<int>(versionNode) != version)
        throw InputError(inputName, "version",
                         "unsupported version; this build reads version " + std::to_string(version));
}

core::Calibration readCalibrationKeys(const cv::FileNode& root, const std::string& inputName) {
    core::Calibration calibration;
    calibration.cameraSize = readSize(root, inputName, "camera_size");
    calibration.cameraMatrix = readEigen<3, 3>(root, inputName, "camera_matrix");
    calibration.cameraDistortion = readEigen<5, 1>(root, inputName, "camera_distortion");
    calibration.projectorSize = readSize(root, inputName, "projector_size");
    calibration.projectorMatrix = readEigen<3, 3>(root, inputName, "projector_matrix");
    calibration.tableToCamera.matrix() = readEigen<4, 4>(root, inputName, "table_to_camera");
    calibration.tableToProjector.matrix() = readEigen<4, 4>(root, inputName, "table_to_projector");
    calibration.displaySize = readSize(root, inputName, "display_size");
    calibration.displayToProjector = readEigen<3, 3>(root, inputName, "display_to_projector");
    if (auto problem = calibration.validate())
        throw InputError(inputName, "", *problem);
    return calibration;
}

void writeCalibrationKeys(cv::FileStorage& storage, const core::Calibration& calibration) {
    writeSize(storage, "camera_size", calibration.cameraSize);
    storage << "camera_matrix" << toMat(calibration.cameraMatrix);
    storage << "camera_distortion" << toMat(calibration.cameraDistortion.transpose());
    writeSize(storage, "projector_size", calibration.projectorSize);
    storage << "projector_matrix" << toMat(calibration.projectorMatrix);
    storage << "table_to_camera" << toMat(calibration.tableToCamera.matrix());
    storage << "table_to_projector" << toMat(calibration.tableToProjector.matrix());
    writeSize(storage, "display_size", calibration.displaySize);
    storage << "display_to_projector" << toMat(calibration.displayToProjector);
}

core::Calibration readCalibrationFile(const std::filesystem::path& path) {
    const cv::FileStorage storage = openYamlForReading(path);
    checkFormatHeader(storage.root(), path.string(), {kCalibrationFormat}, kCalibrationVersion);
    return readCalibrationKeys(storage.root(), path.string());
}

void writeCalibrationFile(const std::filesystem::path& path, const core::Calibration& calibration) {
    if (auto problem = calibration.validate())
        throw InputError(path.string(), "", "refusing to write an invalid calibration: " + *problem);
    cv::FileStorage storage(".yml",
                            cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    storage << "format" << kCalibrationFormat << "version" << kCalibrationVersion;
    writeCalibrationKeys(storage, calibration);
    writeFileAtomically(path, storage.releaseAndGetString());
}

}  // namespace everytouch::io
