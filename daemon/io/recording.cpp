#include "io/recording.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <system_error>

#include <opencv2/imgcodecs.hpp>

#include "io/atomic_file.h"
#include "io/calibration_file.h"
#include "io/input_error.h"

namespace everytouch::io {

namespace {

std::vector<std::string_view> splitFields(std::string_view line) {
    std::vector<std::string_view> fields;
    size_t start = 0;
    while (true) {
        const size_t comma = line.find(',', start);
        fields.push_back(
            line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
        if (comma == std::string_view::npos)
            return fields;
        start = comma + 1;
    }
}

template <typename T>
bool parseNumber(std::string_view text, T& value) {
    while (!text.empty() && text.front() == ' ')
        text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\r'))
        text.remove_suffix(1);
    const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (error != std::errc() || end != text.data() + text.size())
        return false;
    if constexpr (std::is_floating_point_v<T>)
        return std::isfinite(value);
    return true;
}

// Reads a CSV file with the exact header `header`; calls `row(fields, where)` for each non-empty line.
template <typename RowHandler>
void readCsv(const std::filesystem::path& path, const std::string& header, size_t fieldCount,
             RowHandler row) {
    std::ifstream input(path);
    if (!input)
        throw InputError(path.string(), "", "cannot be opened");
    std::string line;
    if (!std::getline(input, line) ||
        (line.ends_with('\r') ? line.substr(0, line.size() - 1) : line) != header)
        throw InputError(path.string(), "line 1", "expected the header \"" + header + "\"");
    for (size_t number = 2; std::getline(input, line); ++number) {
        if (line.empty() || line == "\r")
            continue;
        const std::string where = "line " + std::to_string(number);
        const auto fields = splitFields(line);
        if (fields.size() != fieldCount)
            throw InputError(path.string(), where,
                             "expected " + std::to_string(fieldCount) + " fields, found " +
                                 std::to_string(fields.size()) + " (truncated or malformed line)");
        row(fields, where);
    }
}

std::filesystem::path indexedPath(const std::filesystem::path& directory, const char* folder,
                                  std::uint64_t index) {
    char name[32];
    std::snprintf(name, sizeof name, "%06llu.png", static_cast<unsigned long long>(index));
    return directory / folder / name;
}

std::string sizeText(const cv::Size& size) {
    return std::to_string(size.width) + "x" + std::to_string(size.height);
}

// Checks from its header alone that `path` is a PNG of `size`, before anything is decoded: OpenCV allocates
// the image a header declares before it reads a pixel, and a broken or hostile file may declare a gigapixel.
// `sizeName` says whose size it must have.
void requirePngOfSize(const std::filesystem::path& path, const cv::Size& size, const std::string& sizeName) {
    constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    unsigned char header[24] = {};
    std::ifstream file(path, std::ios::binary);
    if (!file.read(reinterpret_cast<char*>(header), sizeof header) ||
        std::memcmp(header, kSignature, sizeof kSignature) != 0 || std::memcmp(header + 12, "IHDR", 4) != 0)
        throw InputError(path.string(), "", "not a readable PNG image");
    const auto bigEndian = [&header](int at) {
        return (std::uint32_t{header[at]} << 24) | (std::uint32_t{header[at + 1]} << 16) |
               (std::uint32_t{header[at + 2]} << 8) | std::uint32_t{header[at + 3]};
    };
    const std::uint32_t width = bigEndian(16), height = bigEndian(20);
    if (width != static_cast<std::uint32_t>(size.width) || height != static_cast<std::uint32_t>(size.height))
        throw InputError(path.string(), "",
                         "expected the " + sizeName + " " + sizeText(size) + ", found " +
                             std::to_string(width) + "x" + std::to_string(height));
}

// The type of the file at `path`. A path the system refuses outright (a name too long, a loop of links) is an
// input error naming it, not a filesystem exception.
std::filesystem::file_type typeOf(const std::filesystem::path& path) {
    std::error_code error;
    const std::filesystem::file_status status = std::filesystem::status(path, error);
    if (error && status.type() == std::filesystem::file_type::none)
        throw InputError(path.string(), "", "cannot be accessed (" + error.message() + ")");
    return status.type();
}

bool isRegularFile(const std::filesystem::path& path) {
    return typeOf(path) == std::filesystem::file_type::regular;
}

bool isDirectory(const std::filesystem::path& path) {
    return typeOf(path) == std::filesystem::file_type::directory;
}

bool isPresent(const std::filesystem::path& path) {
    return typeOf(path) != std::filesystem::file_type::not_found;
}

// Reads an 8-bit single-channel image of `size` that holds only 0 and 255; `sizeName` says whose size it must
// have.
cv::Mat readBinaryImage(const std::filesystem::path& path, const cv::Size& size,
                        const std::string& sizeName) {
    const std::string name = path.string();
    if (!isRegularFile(path))
        throw InputError(name, "", "missing");
    requirePngOfSize(path, size, sizeName);
    cv::Mat image = cv::imread(name, cv::IMREAD_UNCHANGED);
    if (image.empty())
        throw InputError(name, "", "not a readable image");
    if (image.type() != CV_8UC1)
        throw InputError(name, "",
                         "expected an 8-bit single-channel image, found " +
                             std::to_string(8 * image.elemSize1()) + "-bit with " +
                             std::to_string(image.channels()) +
                             (image.channels() == 1 ? " channel" : " channels"));
    const int nonBinary = image.total() - cv::countNonZero(image == 0) - cv::countNonZero(image == 255);
    if (nonBinary != 0)
        throw InputError(
            name, "",
            "expected only the values 0 and 255, found " + std::to_string(nonBinary) + " other pixels");
    return image;
}

}  // namespace

cv::Mat readPatternImage(const std::filesystem::path& path, cv::Size size) {
    return readBinaryImage(path, size, "projector size") / 255;
}

std::filesystem::path Recording::framePath(const std::filesystem::path& directory, std::uint64_t index) {
    return indexedPath(directory, "frames", index);
}

std::filesystem::path Recording::maskPath(const std::filesystem::path& directory, std::uint64_t index) {
    return indexedPath(directory, "masks", index);
}

Recording Recording::open(const std::filesystem::path& directory) {
    Recording recording;
    recording.directory_ = directory;
    if (!isDirectory(directory))
        throw InputError(directory.string(), "", "not a recording directory");

    const std::filesystem::path rigPath = directory / "rig.yml";
    const std::string rigName = rigPath.string();
    const cv::FileStorage storage = openYamlForReading(rigPath);
    const cv::FileNode root = storage.root();
    checkFormatHeader(root, rigName, {kRecordingFormat, kCalibrationFormat}, kRecordingVersion);
    RigDescription& rig = recording.rig_;
    rig.calibration = readCalibrationKeys(root, rigName);
    const cv::FileNode delta = root["delta"];
    if (delta.empty())
        throw InputError(rigName, "delta", "missing");
    if (!delta.isInt() || static_cast<int>(delta) < 1 || static_cast<int>(delta) > 127)
        throw InputError(rigName, "delta", "expected an integer in 1..127");
    rig.delta = static_cast<int>(delta);
    const cv::FileNode frameRate = root["frame_rate"];
    if (frameRate.empty())
        throw InputError(rigName, "frame_rate", "missing");
    if (!frameRate.isReal() && !frameRate.isInt())
        throw InputError(rigName, "frame_rate", "expected a number");
    rig.frameRate = static_cast<double>(frameRate);
    if (!std::isfinite(rig.frameRate) || rig.frameRate <= 0)
        throw InputError(rigName, "frame_rate", "expected a positive finite number");
    const cv::FileNode pattern = root["pattern"];
    if (pattern.empty())
        throw InputError(rigName, "pattern", "missing");
    if (!pattern.isString() || pattern.string().empty())
        throw InputError(rigName, "pattern", "expected a file name");
    rig.pattern = readPatternImage(directory / pattern.string(), rig.calibration.projectorSize);

    const std::filesystem::path framesPath = directory / "frames.csv";
    if (!isRegularFile(framesPath))
        throw InputError(framesPath.string(), "", "missing");
    readCsv(framesPath, "index,timestamp_us,polarity", 3, [&](const auto& fields, const std::string& where) {
        FrameEntry entry;
        int polarity = 0;
        if (!parseNumber(fields[0], entry.index))
            throw InputError(framesPath.string(), where, "index: expected a non-negative integer");
        if (!parseNumber(fields[1], entry.timestampUs))
            throw InputError(framesPath.string(), where, "timestamp_us: expected an integer");
        if (!parseNumber(fields[2], polarity) || (polarity != 1 && polarity != -1))
            throw InputError(framesPath.string(), where, "polarity: expected 1 or -1");
        entry.polarity = static_cast<core::Polarity>(polarity);
        if (!recording.frames_.empty()) {
            const FrameEntry& previous = recording.frames_.back();
            if (entry.index <= previous.index)
                throw InputError(framesPath.string(), where, "index: must increase from line to line");
            if (entry.timestampUs < previous.timestampUs)
                throw InputError(framesPath.string(), where, "timestamp_us: goes back in time");
        }
        if (!isRegularFile(framePath(directory, entry.index)))
            throw InputError(framePath(directory, entry.index).string(), "",
                             "missing (listed in frames.csv " + where + ")");
        recording.frames_.push_back(entry);
    });

    const std::filesystem::path masksPath = directory / "masks";
    if (isPresent(masksPath)) {
        if (!isDirectory(masksPath))
            throw InputError(masksPath.string(), "", "expected a directory of hand masks");
        recording.hasMasks_ = true;
        for (const FrameEntry& entry : recording.frames_)
            if (!isRegularFile(maskPath(directory, entry.index)))
                throw InputError(maskPath(directory, entry.index).string(), "",
                                 "missing (masks/ needs a mask for every frame in frames.csv)");
    }

    const std::filesystem::path truthPath = directory / "truth.csv";
    if (isPresent(truthPath)) {
        recording.hasTruth_ = true;
        readCsv(truthPath, "index,id,x,y,height_mm", 5, [&](const auto& fields, const std::string& where) {
            core::FingerTruth finger;
            if (!parseNumber(fields[0], finger.frameIndex))
                throw InputError(truthPath.string(), where, "index: expected a non-negative integer");
            if (!parseNumber(fields[1], finger.id))
                throw InputError(truthPath.string(), where, "id: expected a non-negative integer");
            if (!parseNumber(fields[2], finger.x))
                throw InputError(truthPath.string(), where, "x: expected a finite number");
            if (!parseNumber(fields[3], finger.y))
                throw InputError(truthPath.string(), where, "y: expected a finite number");
            if (!parseNumber(fields[4], finger.heightMm) || finger.heightMm < 0)
                throw InputError(truthPath.string(), where, "height_mm: expected a finite number >= 0");
            if (!recording.truth_.empty() && finger.frameIndex < recording.truth_.back().frameIndex)
                throw InputError(truthPath.string(), where, "index: frames must be in increasing order");
            recording.truth_.push_back(finger);
        });
    }
    return recording;
}

core::Frame Recording::loadFrame(std::size_t position) const {
    const FrameEntry& entry = frames_.at(position);
    const std::filesystem::path path = framePath(directory_, entry.index);
    core::Frame frame;
    requirePngOfSize(path, rig_.calibration.cameraSize, "camera size");
    frame.image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
    if (frame.image.empty())
        throw InputError(path.string(), "", "not a readable image");
    if (frame.image.type() != CV_8UC1 && frame.image.type() != CV_8UC3)
        throw InputError(path.string(), "", "expected an 8-bit gray or BGR image");
    frame.index = entry.index;
    frame.timestampUs = entry.timestampUs;
    frame.polarity = entry.polarity;
    return frame;
}

cv::Mat Recording::loadMask(std::size_t position) const {
    if (!hasMasks_)
        throw std::logic_error("loadMask: the recording has no masks");
    return readBinaryImage(maskPath(directory_, frames_.at(position).index), rig_.calibration.cameraSize,
                           "camera size");
}

void writePatternImage(const std::filesystem::path& path, const cv::Mat& pattern) {
    std::vector<uchar> png;
    if (!cv::imencode(".png", pattern * 255, png))
        throw InputError(path.string(), "", "cannot be encoded as PNG");
    writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

RecordingWriter::RecordingWriter(const std::filesystem::path& directory, const RigDescription& rig,
                                 bool withTruth, bool withMasks)
    : directory_(directory), cameraSize_(rig.calibration.cameraSize), withMasks_(withMasks) {
    std::error_code error;
    if (isPresent(directory) && !std::filesystem::is_empty(directory))
        throw InputError(directory.string(), "", "exists and is not empty; choose a new recording directory");
    if (!std::filesystem::create_directories(directory / "frames", error) && error)
        throw InputError(directory.string(), "", "cannot be created: " + error.message());
    if (withMasks && !std::filesystem::create_directory(directory / "masks", error) && error)
        throw InputError((directory / "masks").string(), "", "cannot be created: " + error.message());

    cv::FileStorage storage(".yml",
                            cv::FileStorage::WRITE | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
    storage << "format" << kRecordingFormat << "version" << kRecordingVersion;
    writeCalibrationKeys(storage, rig.calibration);
    storage << "delta" << rig.delta << "frame_rate" << rig.frameRate << "pattern"
            << "pattern.png";
    writeFileAtomically(directory / "rig.yml", storage.releaseAndGetString());
    writePatternImage(directory / "pattern.png", rig.pattern);

    const auto openTable = [&](const char* name, std::string_view header, UniqueFd& table, off_t& size) {
        const std::filesystem::path path = directory / name;
        table.reset(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
        if (!table)
            throw InputError(path.string(), "", std::string("cannot be written: ") + std::strerror(errno));
        appendLine(table, header, path, size);
    };
    openTable("frames.csv", "index,timestamp_us,polarity\n", framesCsv_, framesSize_);
    if (withTruth)
        openTable("truth.csv", "index,id,x,y,height_mm\n", truthCsv_, truthSize_);
    framesComplete_ = framesSize_;
    truthComplete_ = truthSize_;
}

void RecordingWriter::begin(std::uint64_t index) {
    if (openIndex_ == index)
        return;
    completeOpenFrame();
    openIndex_ = index;
}

void RecordingWriter::completeOpenFrame() {
    openIndex_.reset();
    framesComplete_ = framesSize_;
    truthComplete_ = truthSize_;
    openImages_.clear();
    openFrameListed_ = false;
}

template <typename Write>
void RecordingWriter::guarded(std::uint64_t index, Write write) {
    if (stopped_)
        throw std::logic_error(directory_.string() + ": the recording stopped at a failed write");
    begin(index);
    try {
        write();
    } catch (...) {
        takeBackOpenFrame();
        stopped_ = true;
        throw;
    }
}

void RecordingWriter::takeBackOpenFrame() noexcept {
    std::error_code ignored;
    for (const std::filesystem::path& image : openImages_)
        std::filesystem::remove(image, ignored);
    openImages_.clear();
    // What cannot be cut off was not written either: the disk refused it.
    if (framesCsv_ && ::ftruncate(framesCsv_.get(), framesComplete_) == 0)
        framesSize_ = framesComplete_;
    if (truthCsv_ && ::ftruncate(truthCsv_.get(), truthComplete_) == 0)
        truthSize_ = truthComplete_;
    if (openFrameListed_)
        --framesWritten_;
    openFrameListed_ = false;
}

bool RecordingWriter::encodePng(const cv::Mat& image, std::vector<uchar>& png) {
    return cv::imencode(".png", image, png);
}

void RecordingWriter::encodeOpenImage(const std::filesystem::path& path, const cv::Mat& image) {
    if (!encodePng(image, encoded_))
        throw std::runtime_error(path.string() + ": the image cannot be encoded as PNG");
}

void RecordingWriter::writeImage(const std::filesystem::path& path, std::span<const uchar> png) {
    UniqueFd file(::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644));
    if (!file)
        throw std::system_error(errno, std::generic_category(), path.string());
    openImages_.push_back(path);
    writeAll(file, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()), path);
    if (::close(file.release()) != 0)
        throw std::system_error(errno, std::generic_category(), path.string());
}

void RecordingWriter::writeAll(const UniqueFd& file, std::string_view bytes,
                               const std::filesystem::path& path) {
    while (!bytes.empty()) {
        const ssize_t written = ::write(file.get(), bytes.data(), bytes.size());
        if (written < 0 && errno == EINTR)
            continue;
        if (written <= 0)
            throw std::system_error(written < 0 ? errno : ENOSPC, std::generic_category(), path.string());
        bytes.remove_prefix(static_cast<std::size_t>(written));
    }
}

void RecordingWriter::appendLine(const UniqueFd& table, std::string_view line,
                                 const std::filesystem::path& path, off_t& size) {
    writeAll(table, line, path);
    size += static_cast<off_t>(line.size());
}

void RecordingWriter::addFrame(const core::Frame& frame) {
    guarded(frame.index,
            [&] { encodeOpenImage(Recording::framePath(directory_, frame.index), frame.image); });
    addFrame(frame, encoded_);
}

void RecordingWriter::addFrame(const core::Frame& frame, std::span<const uchar> png) {
    guarded(frame.index, [&] {
        writeImage(Recording::framePath(directory_, frame.index), png);
        char line[96];
        const int length =
            std::snprintf(line, sizeof line, "%llu,%lld,%d\n", static_cast<unsigned long long>(frame.index),
                          static_cast<long long>(frame.timestampUs), static_cast<int>(frame.polarity));
        appendLine(framesCsv_, std::string_view(line, static_cast<std::size_t>(length)),
                   directory_ / "frames.csv", framesSize_);
        ++framesWritten_;
        openFrameListed_ = true;
    });
}

void RecordingWriter::addTruth(const std::vector<core::FingerTruth>& fingers) {
    if (!truthCsv_)
        throw std::logic_error("addTruth: the recording was started without truth");
    if (fingers.empty())
        return;
    guarded(fingers.front().frameIndex, [&] {
        char line[160];
        for (const core::FingerTruth& finger : fingers) {
            const int length = std::snprintf(line, sizeof line, "%llu,%u,%.3f,%.3f,%.3f\n",
                                             static_cast<unsigned long long>(finger.frameIndex), finger.id,
                                             finger.x, finger.y, finger.heightMm);
            appendLine(truthCsv_, std::string_view(line, static_cast<std::size_t>(length)),
                       directory_ / "truth.csv", truthSize_);
        }
    });
}

void RecordingWriter::checkMask(const cv::Mat& mask) const {
    if (!withMasks_)
        throw std::logic_error("addMask: the recording was started without masks");
    if (mask.type() != CV_8UC1 || mask.size() != cameraSize_)
        throw std::invalid_argument("addMask: expected an 8-bit single-channel mask of the camera size");
}

void RecordingWriter::addMask(std::uint64_t frameIndex, const cv::Mat& mask) {
    // A mask refused takes its frame back and stops the writer, as a failed write does: the frame's files
    // are kept or dropped together.
    guarded(frameIndex, [&] {
        checkMask(mask);
        encodeOpenImage(Recording::maskPath(directory_, frameIndex), mask);
    });
    addMask(frameIndex, encoded_);
}

void RecordingWriter::addMask(std::uint64_t frameIndex, std::span<const uchar> png) {
    if (!withMasks_)
        throw std::logic_error("addMask: the recording was started without masks");
    guarded(frameIndex, [&] { writeImage(Recording::maskPath(directory_, frameIndex), png); });
}

void RecordingWriter::flush() {
    if (stopped_)
        return;
    completeOpenFrame();
    for (const UniqueFd* table : {&framesCsv_, &truthCsv_})
        if (*table && ::fdatasync(table->get()) != 0)
            throw std::system_error(errno, std::generic_category(), directory_.string() + ": the tables");
}

}  // namespace everytouch::io
