#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "core/calibration.h"
#include "core/contact.h"
#include "core/frame.h"
#include "io/handles.h"
#include "io/rig_description.h"

namespace everytouch::io {

inline constexpr const char* kRecordingFormat = "everytouch-recording";
inline constexpr int kRecordingVersion = 1;

struct FrameEntry {
    std::uint64_t index = 0;
    std::int64_t timestampUs = 0;
    core::Polarity polarity = core::Polarity::Positive;
};

// A recording directory (docs/architecture.md, "Recording"). Opening checks every file it names, so a
// recording either opens completely or not at all; frame images are read on demand.
class Recording {
public:
    // Throws InputError naming the file and the field or line at fault.
    static Recording open(const std::filesystem::path& directory);

    const RigDescription& rig() const { return rig_; }
    const std::vector<FrameEntry>& frames() const { return frames_; }
    const std::vector<core::FingerTruth>& truth() const { return truth_; }  // empty without truth.csv
    bool hasTruth() const { return hasTruth_; }
    // The recording has masks/, and then a mask file for every frame.
    bool hasMasks() const { return hasMasks_; }

    // Reads frame number `position` (0 .. frames().size()-1); throws InputError if the image is unreadable or
    // does not match camera_size.
    core::Frame loadFrame(std::size_t position) const;

    // Reads the ground-truth hand mask of frame number `position` (CV_8UC1, camera size, 255 where the camera
    // sees a hand); only when hasMasks(). Throws InputError if the image is unreadable, not 8-bit single
    // channel, not of camera_size or holds values other than 0 and 255.
    cv::Mat loadMask(std::size_t position) const;

    static std::filesystem::path framePath(const std::filesystem::path& directory, std::uint64_t index);
    static std::filesystem::path maskPath(const std::filesystem::path& directory, std::uint64_t index);

private:
    std::filesystem::path directory_;
    RigDescription rig_;
    std::vector<FrameEntry> frames_;
    std::vector<core::FingerTruth> truth_;
    bool hasTruth_ = false;
    bool hasMasks_ = false;
};

// Writes a code pattern (CV_8UC1, 0 or 1) as a recording's pattern.png holds it, 255 on 1-bits, replacing
// `path` atomically. Throws std::system_error or InputError naming the path.
void writePatternImage(const std::filesystem::path& path, const cv::Mat& pattern);
// Reads a pattern as writePatternImage writes it: an 8-bit PNG of `size` holding only 0 and 255. Returns
// CV_8UC1, 0 or 1. Throws InputError naming the path for anything else.
cv::Mat readPatternImage(const std::filesystem::path& path, cv::Size size);

// Writes a recording directory from any rig. The directory must not exist or be empty. With truth, truth.csv
// takes the fingers of every frame; with masks, masks/ takes the hand mask of every frame.
//
// A frame's image, mask and lines are kept or dropped together: when a write fails (the disk full), what was
// written of the frame being added is taken away again, so that the recording holds every frame before it
// and reads as any other; the call throws std::system_error naming the file, and every later call
// std::logic_error. A frame is complete once a call names the next frame's index (or flush() came).
class RecordingWriter {
public:
    RecordingWriter(const std::filesystem::path& directory, const RigDescription& rig, bool withTruth,
                    bool withMasks = false);

    void addFrame(const core::Frame& frame);
    // The same with the frame's image already encoded by encodePng (on another thread: encoding is what
    // takes the time).
    void addFrame(const core::Frame& frame, std::span<const uchar> png);
    void addTruth(const std::vector<core::FingerTruth>& fingers);
    // The hand mask of frame `frameIndex`: CV_8UC1, camera size, 0 and 255. Throws what checkMask throws.
    void addMask(std::uint64_t frameIndex, const cv::Mat& mask);
    // The same with a mask that passed checkMask, encoded by encodePng.
    void addMask(std::uint64_t frameIndex, std::span<const uchar> png);
    // Throws std::logic_error for a writer without masks and std::invalid_argument for a mask of another type
    // or size.
    void checkMask(const cv::Mat& mask) const;
    // An image as the recording's files hold it (PNG); false when it cannot be encoded. Safe to call from any
    // thread.
    [[nodiscard]] static bool encodePng(const cv::Mat& image, std::vector<uchar>& png);
    // Completes the last frame and puts the tables on the disk (fdatasync).
    void flush();

    // Frames in frames.csv.
    std::uint64_t framesWritten() const { return framesWritten_; }
    // Whether a write failed: the writer takes nothing more.
    bool stopped() const { return stopped_; }

private:
    // Starts frame `index` unless it is the one being written: the one before is then complete.
    void begin(std::uint64_t index);
    // The frame being written is complete: a failure later no longer takes it back.
    void completeOpenFrame();
    // Runs `write`; when it throws, takes the open frame away and stops the writer.
    template <typename Write>
    void guarded(std::uint64_t index, Write write);
    void takeBackOpenFrame() noexcept;
    // Encodes an image of the frame being written into encoded_, or throws naming its file.
    void encodeOpenImage(const std::filesystem::path& path, const cv::Mat& image);
    void writeImage(const std::filesystem::path& path, std::span<const uchar> png);
    static void writeAll(const UniqueFd& file, std::string_view bytes, const std::filesystem::path& path);
    // Appends to frames.csv or truth.csv, whose bytes `size` counts.
    static void appendLine(const UniqueFd& table, std::string_view line, const std::filesystem::path& path,
                           off_t& size);

    std::filesystem::path directory_;
    cv::Size cameraSize_;
    bool withMasks_;
    UniqueFd framesCsv_;
    UniqueFd truthCsv_;
    off_t framesSize_ = 0, truthSize_ = 0;           // bytes written
    off_t framesComplete_ = 0, truthComplete_ = 0;   // bytes of the complete frames
    std::optional<std::uint64_t> openIndex_;         // the frame being written
    std::vector<std::filesystem::path> openImages_;  // its files
    bool openFrameListed_ = false;                   // its line is in frames.csv
    std::uint64_t framesWritten_ = 0;
    bool stopped_ = false;
    std::vector<uchar> encoded_;
};

}  // namespace everytouch::io
