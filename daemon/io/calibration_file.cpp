#include "io/calibration_file.h"

#include <array>
#include <cmath>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>

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
    // OpenCV allocates the rows and columns a matrix node claims before it reads its data: a file that
    // claims billions of them would exhaust the memory. Only a node that holds as many numbers as it claims,
    // and no more than a calibration needs, reaches it.
    constexpr int kLargestSide = 16;
    const cv::FileNode claimedRows = node.isMap() ? node["rows"] : cv::FileNode();
    const cv::FileNode claimedCols = node.isMap() ? node["cols"] : cv::FileNode();
    const cv::FileNode data = node.isMap() ? node["data"] : cv::FileNode();
    if (!claimedRows.isInt() || !claimedCols.isInt() || !data.isSeq() || static_cast<int>(claimedRows) < 1 ||
        static_cast<int>(claimedRows) > kLargestSide || static_cast<int>(claimedCols) < 1 ||
        static_cast<int>(claimedCols) > kLargestSide ||
        data.size() !=
            static_cast<std::size_t>(static_cast<int>(claimedRows) * static_cast<int>(claimedCols)))
        throw InputError(inputName, key,
                         "expected an opencv-matrix of at most " + std::to_string(kLargestSide) + "x" +
                             std::to_string(kLargestSide) + " numbers, rows x cols of them");
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

// What OpenCV 4.6's YAML parser cannot survive, found by fuzzing (tests/fuzz): a mapping key that is empty
// (a colon with nothing but blanks since the line's start, a "{" or a ","; outside quotes and comments) ends
// the process; text after a document marker "---" on its line, or a document whose first key is indented,
// can make it loop for ever. Says where.
std::optional<std::string> findUnparsable(std::string_view text) {
    bool keyFound = false;
    for (std::size_t start = 0, line = 1; start < text.size(); ++line) {
        const std::size_t end = std::min(text.find('\n', start), text.size());
        const std::string_view whole = text.substr(start, end - start);
        const std::size_t indent = std::min(whole.find_first_not_of(" \t\r"), whole.size());
        const std::string_view content = whole.substr(indent);
        start = end + 1;
        if (content.substr(0, 3) == "---" && content.find_first_not_of(" \t\r", 3) != std::string_view::npos)
            return "line " + std::to_string(line) + ": something after the document marker ---";
        if (content.empty() || content.front() == '#' || content.front() == '%' ||
            content.substr(0, 3) == "---")
            continue;
        // The document's own keys start at the line's beginning; an indented first one can make the parser
        // loop for ever when a line further down is less indented.
        if (!keyFound && indent > 0)
            return "line " + std::to_string(line) + ": the document's first key is indented";
        keyFound = true;
    }
    int line = 1;
    char previous = '\n';         // the character before this one on its line
    char lastSignificant = '\n';  // the last one that was not a blank
    char quote = 0;
    bool comment = false;
    const auto startsValue = [](char c) {
        return std::string_view("\n:[{,-").find(c) != std::string_view::npos;
    };
    for (const char c : text) {
        if (c == '\n') {
            ++line;
            comment = false;
            quote = 0;
            previous = lastSignificant = '\n';
            continue;
        }
        const char before = previous;
        previous = c;
        if (comment)
            continue;
        if (quote) {
            if (c == quote)
                quote = 0;
            continue;
        }
        if ((c == '"' || c == '\'') && startsValue(lastSignificant)) {
            quote = c;  // a quoted scalar; a quote inside a plain one is just a character
        } else if (c == '#' && (before == '\n' || before == ' ' || before == '\t')) {
            comment = true;  // comments begin at the line's start or after a blank
            continue;
        } else if (c == ':' &&
                   (lastSignificant == '\n' || lastSignificant == '{' || lastSignificant == ',')) {
            return "line " + std::to_string(line) + ": a key without a name";
        }
        if (c != ' ' && c != '\t' && c != '\r')
            lastSignificant = c;
    }
    return std::nullopt;
}

}  // namespace

cv::FileStorage openYamlForReading(const std::filesystem::path& path) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
        throw InputError(path.string(), "", "no such file");
    // The text is read here and checked before OpenCV's parser sees it (findUnparsable).
    // In pieces, up to one byte past the largest file: a 1 MiB buffer allocated and cleared for each file
    // took most of a fuzzer's time per input.
    std::ifstream in(path, std::ios::binary);
    std::string text;
    constexpr std::size_t kLargestFile = 1 << 20;
    std::array<char, 16384> piece;
    while (text.size() <= kLargestFile && in.read(piece.data(), piece.size()).gcount() > 0)
        text.append(piece.data(), static_cast<std::size_t>(in.gcount()));
    if (in.bad())
        throw InputError(path.string(), "", "cannot be read");
    if (text.size() > kLargestFile)
        throw InputError(path.string(), "", "larger than any calibration (1 MiB)");
    if (const std::optional<std::string> problem = findUnparsable(text))
        throw InputError(path.string(), "", "not a valid YAML document (" + *problem + ")");
    cv::FileStorage storage;
    try {
        storage.open(text, cv::FileStorage::READ | cv::FileStorage::FORMAT_YAML | cv::FileStorage::MEMORY);
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
