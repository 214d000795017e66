// everytouch-eval: scores the pipeline's stages on a recording against its ground truth.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "core/fingertips.h"
#include "eval/contact_sheet.h"
#include "eval/detected_contacts.h"
#include "eval/fingertip_scoring.h"
#include "eval/segmentation_evaluation.h"
#include "eval/segmentation_methods.h"
#include "eval/segmentation_report.h"
#include "eval/source_run.h"
#include "eval/touch_plot.h"
#include "eval/touch_report.h"
#include "eval/touch_scoring.h"
#include "eval/touch_trials.h"
#include "io/input_error.h"
#include "io/recording.h"
#include "io/rig_spec.h"
#include "io/sim_source.h"
#include "io/touch_log.h"
#include "version.h"

namespace {

using namespace everytouch;

constexpr int kExitFailure = 1;
constexpr int kExitBadInput = 2;

struct SegmentationArguments {
    std::string recording;
    std::string json;
    std::string png;
    std::vector<std::string> methodNames;  // empty: all
    // The width of a finger, mm: an adult index finger is about 16 mm across at its last joint (the
    // simulated hand's finger bones are 13-18.5 mm wide). It scales the fingertip finder and the match
    // radius.
    double fingerWidthMm = 16.0;
    eval::MethodOptions methods;
    eval::ContactSheetOptions sheet;
};

CLI::App* addSegmentationCommand(CLI::App& app, SegmentationArguments& arguments) {
    CLI::App* command = app.add_subcommand(
        "segmentation",
        "Score hand segmentation on every pair of a recording with masks: precision, recall and F_beta per "
        "method, fingertip detection rate and error against truth.csv");
    command->add_option("REC", arguments.recording, "Recording directory (rig.yml, frames, masks/)")
        ->required();
    command->add_option("--json", arguments.json, "Also write the results as JSON to FILE");
    command->add_option("--png", arguments.png, "Draw a contact sheet (texture, truth, each method's mask)");
    command
        ->add_option("--methods", arguments.methodNames,
                     "Score only these methods (ours, paper, SCM, BkSub), comma-separated")
        ->delimiter(',');
    command->add_option("--rows", arguments.sheet.rows, "Pairs on the contact sheet")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    command
        ->add_option("--finger-width-mm", arguments.fingerWidthMm,
                     "Width of a finger: the fingertip finder's scale and the match radius")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    command
        ->add_option("--background-pairs", arguments.methods.background.samples,
                     "Pairs sharing no frame at the recording's start whose median is BkSub's background")
        ->capture_default_str()
        ->check(CLI::Range(3, 1000));
    command->footer(
        "Methods:\n"
        "  ours   the pipeline's segmentation by the embedded code (core::HandSegmenter).\n"
        "  paper  the paper's method as published: HC saliency, mean shift, confidence fusion, closing.\n"
        "  SCM    the statistical skin-colour model of Jones & Rehg (IJCV 2002): their published RGB "
        "Gaussian\n"
        "         mixtures (16 skin, 16 non-skin kernels), maximum-likelihood decision, on the texture T.\n"
        "  BkSub  background subtraction. The paper's predecessor predicts the empty table from the "
        "projected\n"
        "         content through its calibration; a recording does not carry the content, so here the\n"
        "         background is the per-pixel median of the textures of the first pairs (a recording should\n"
        "         start with the table empty and the content still). A pixel is hand where a channel "
        "differs\n"
        "         by more than the threshold at which camera noise, measured in the same pairs, marks one\n"
        "         pixel per frame.\n"
        "Scores: pixel counts summed over all pairs (micro average) and per-pair means, over the whole "
        "frame\n"
        "(as the paper) and within the display; F_beta with beta^2 = 0.3 (paper eq. 23). Fingertips found\n"
        "on each mask are matched one to one to truth.csv's fingers, mapped into the camera through\n"
        "rig.yml's calibration, within one finger width.\n"
        "Only rig.yml (calibration, pattern, delta), frames, masks/ and truth.csv are read. See\n"
        "docs/evaluation.md.");
    return command;
}

int runSegmentation(const SegmentationArguments& arguments) {
    const io::Recording recording = io::Recording::open(arguments.recording);
    if (!recording.hasMasks())
        throw io::InputError(
            arguments.recording, "masks/",
            "missing; segmentation is scored against the truth masks masks/NNNNNN.png, which "
            "everytouchd --record writes on the simulated rig");
    const eval::TruthToCamera truthToCamera(recording.rig().calibration, arguments.fingerWidthMm);
    std::vector<eval::SegmentationMethod> methods = eval::segmentationMethods(recording, arguments.methods);
    if (!arguments.methodNames.empty()) {
        std::vector<eval::SegmentationMethod> chosen;
        for (const std::string& name : arguments.methodNames) {
            auto found =
                std::find_if(methods.begin(), methods.end(),
                             [&](const eval::SegmentationMethod& method) { return method.name == name; });
            if (found == methods.end())
                throw io::InputError("--methods " + name, "", "not a method (ours, paper, SCM, BkSub)");
            chosen.push_back(*found);
        }
        methods = chosen;
    }

    // The finder as the pipeline sets it up for this rig; its pads are what a touch is reported at.
    const core::FingertipOptions fingertipOptions =
        core::rigFingertipOptions(recording.rig().calibration, arguments.fingerWidthMm);
    if (const auto problem = fingertipOptions.validate())
        throw io::InputError(arguments.recording + "/rig.yml", "",
                             "no fingertip finder for this rig: " + *problem);
    core::FingertipScratch scratch;
    core::Fingertips found;
    const eval::FingertipFinder findFingertips = [&](const cv::Mat& mask, const cv::Mat& judged,
                                                     std::vector<Eigen::Vector2d>& pads) {
        core::findFingertips(mask, fingertipOptions, scratch, found, judged);
        pads.clear();
        for (const core::Fingertip& fingertip : found)
            pads.push_back(fingertip.pad);
    };
    const eval::SegmentationReport report = eval::evaluateSegmentation(
        recording, arguments.recording, methods, findFingertips, truthToCamera, arguments.fingerWidthMm);
    std::fputs(eval::segmentationTable(report).c_str(), stdout);

    if (!arguments.json.empty()) {
        std::ofstream out(arguments.json);
        out << eval::segmentationJson(report).dump(2) << '\n';
        if (!out)
            throw std::runtime_error(arguments.json + ": cannot be written");
    }
    if (!arguments.png.empty()) {
        std::vector<std::size_t> positions = report.handPositions;
        if (positions.empty())
            for (std::size_t position = 1; position < recording.frames().size(); ++position)
                positions.push_back(position);
        const cv::Mat sheet = eval::renderContactSheet(recording, positions, methods, findFingertips,
                                                       truthToCamera, arguments.sheet);
        if (!cv::imwrite(arguments.png, sheet))
            throw std::runtime_error(arguments.png + ": cannot be written");
    }
    return 0;
}

struct TouchArguments {
    std::string recording;
    std::string log;  // empty: run the pipeline on the recording
    std::string rig;  // instead of a recording: a simulated rig, run live
    std::size_t frames = 0;
    std::string json;
    std::string png;
    std::string trace;
    // The match radius, mm: half a finger width (an adult index finger is about 16 mm across), the distance
    // from a finger's contact point to the middle between it and a neighbour resting beside it.
    double matchRadiusMm = 8.0;
    // Where the pipeline reports a touch, mm: the daemon's default ([Touch] HeightMm=).
    double touchHeightMm = 3.0;
    // The paper's claim: no touch is reported with the finger 8 mm or more above the table.
    double highHoverMm = 8.0;
};

CLI::App* addTouchCommand(CLI::App& app, TouchArguments& arguments) {
    CLI::App* command =
        app.add_subcommand("touches",
                           "Score detected touches against the ground truth (truth.csv, or the simulated "
                           "rig's own with --rig): FRR "
                           "and FAR per tap trial, touch point error epsilon, "
                           "touch-down latency, drag deviation, id swaps, hover height error");
    CLI::Option* recording =
        command->add_option("REC", arguments.recording, "Recording directory with truth.csv");
    command
        ->add_option("LOG", arguments.log,
                     "Touch log made from REC (everytouchd --rig replay:REC --log LOG); without it the "
                     "pipeline runs on REC")
        ->needs(recording);
    CLI::Option* rig = command->add_option(
        "--rig", arguments.rig,
        "Instead of REC, run the pipeline live on a simulated rig, sim[:SCENARIO][,key=value...] as "
        "everytouchd takes it, without recording its frames");
    command
        ->add_option("--frames", arguments.frames,
                     "With --rig: frames to run (the rig's own duration= otherwise)")
        ->needs(rig)
        ->check(CLI::PositiveNumber);
    recording->excludes(rig);
    command->add_option("--json", arguments.json, "Also write the results as JSON to FILE");
    command->add_option("--png", arguments.png,
                        "Plot true (green) and detected (red) touch-down points over the display");
    command->add_option(
        "--trace", arguments.trace,
        "Write one CSV row per true finger and frame: its truth and the contact matched to it "
        "(id, height, touching, position)");
    command
        ->add_option("--match-radius-mm", arguments.matchRadiusMm,
                     "How far a contact may lie from a true contact point and still be that finger")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    command
        ->add_option("--touch-height-mm", arguments.touchHeightMm,
                     "Touch height the contacts are detected with (the pipeline's without LOG, the daemon's "
                     "with it); a touch-down while a true pad is this low is not false")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    command
        ->add_option("--high-hover-mm", arguments.highHoverMm,
                     "Fingers at least this high must never be reported touching")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    command->footer(
        "A trial is a maximal run of frames in which one finger's pad is on the table (truth height 0). In\n"
        "every frame true fingers and detected contacts (palms left out) are matched one to one, nearest\n"
        "first, within the match radius (converted to display pixels with rig.yml's calibration).\n"
        "  FRR      trials in which no matching contact touches / trials\n"
        "  FAR      touch-downs (a contact going to touch) with no true touching finger within the radius\n"
        "           at that frame, per true trial; also given as a count\n"
        "  epsilon  distance from the detected touch point to the true contact point (paper eq. 24) at the\n"
        "           trial's reported touch-down, and over every frame both touch, display pixels\n"
        "  latency  frames from the trial's first frame to the first frame a matching contact touches\n"
        "  drag     distance of a touching contact to the true path, over trials moving beyond the radius\n"
        "  id swaps changes of the matched contact's id while the finger stays touching\n"
        "  hover    |height_mm - truth| of hovering fingers matched to a contact, also by band\n"
        "See docs/evaluation.md.");
    return command;
}

// Scores detected contacts against the truth and prints (and writes) the results. rigName: where `rig` was
// read, for a message.
int reportTouches(const TouchArguments& arguments, const std::string& sourceName, const std::string& rigName,
                  const io::RigDescription& rig, const eval::TruthFrames& truth,
                  const eval::DetectedFrames& detected) {
    eval::TouchScoringOptions options;
    options.matchRadiusPx = eval::matchRadiusPx(rig.calibration, arguments.matchRadiusMm);
    options.highHoverMm = arguments.highHoverMm;
    options.touchHeightMm = arguments.touchHeightMm;
    if (const auto problem = options.validate())
        throw io::InputError(rigName, "", *problem);
    const eval::TouchScore score = eval::scoreTouches(truth, detected, options);
    const eval::TouchSource source{sourceName, arguments.log, arguments.matchRadiusMm, rig.frameRate};
    std::fputs(eval::touchTable(source, score).c_str(), stdout);

    if (!arguments.json.empty()) {
        std::ofstream out(arguments.json);
        out << eval::touchJson(source, score).dump(2) << '\n';
        if (!out)
            throw std::runtime_error(arguments.json + ": cannot be written");
    }
    if (!arguments.trace.empty()) {
        std::ofstream out(arguments.trace);
        eval::writeTouchTrace(out, truth, detected, options.matchRadiusPx);
        if (!out)
            throw std::runtime_error(arguments.trace + ": cannot be written");
    }
    if (!arguments.png.empty() &&
        !cv::imwrite(arguments.png, eval::plotTouchDowns(score, rig.calibration.displaySize)))
        throw std::runtime_error(arguments.png + ": cannot be written");
    return 0;
}

int runTouchesOnRig(const TouchArguments& arguments) {
    const io::RigSpec spec = io::RigSpec::parse(arguments.rig);
    if (spec.kind != io::RigSpec::Kind::Sim)
        throw io::InputError("--rig " + arguments.rig, "",
                             "only the simulated rig knows the truth to score against; score a recording as "
                             "REC instead");
    io::SimSource source(spec, /*paced=*/false);
    if (arguments.frames == 0 && source.endless())
        throw io::InputError("--rig " + arguments.rig, "",
                             "runs without end; give --frames N or duration=SECONDS in the spec");
    const eval::SourceRun run = eval::runOnSource(source, "--rig " + arguments.rig, arguments.frames,
                                                  core::DetectionOptions{}, arguments.touchHeightMm);
    return reportTouches(arguments, arguments.rig, "--rig " + arguments.rig, run.rig, run.truth,
                         run.detected);
}

int runTouches(const TouchArguments& arguments) {
    if (!arguments.rig.empty())
        return runTouchesOnRig(arguments);
    if (arguments.recording.empty())
        throw io::InputError("touches", "", "give a recording REC or a simulated rig with --rig");
    const io::Recording recording = io::Recording::open(arguments.recording);
    if (!recording.hasTruth())
        throw io::InputError(arguments.recording, "truth.csv",
                             "missing; touches are scored against the fingers truth.csv lists, which "
                             "everytouchd --record writes on the simulated rig");
    eval::DetectedFrames detected;
    if (arguments.log.empty())
        detected = eval::contactsFromPipeline(recording, core::DetectionOptions{}, arguments.touchHeightMm);
    else
        detected = eval::contactsFromLog(recording, io::readTouchLog(arguments.log), arguments.log);
    return reportTouches(arguments, arguments.recording, arguments.recording + "/rig.yml", recording.rig(),
                         eval::truthFrames(recording), detected);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"everytouch-eval - scores everytouch's stages on recordings against their ground truth"};
    app.set_version_flag("--version", std::string("everytouch-eval ") + kVersion);
    app.require_subcommand(1);
    app.footer("Exit status: 0 success, 1 failure, 2 bad input (option, recording, missing ground truth).");
    SegmentationArguments segmentation;
    CLI::App* segmentationCommand = addSegmentationCommand(app, segmentation);
    TouchArguments touches;
    CLI::App* touchCommand = addTouchCommand(app, touches);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        const int status = app.exit(error);
        return status == 0 ? 0 : kExitBadInput;
    }
    cv::setNumThreads(1);
    try {
        if (*segmentationCommand)
            return runSegmentation(segmentation);
        if (*touchCommand)
            return runTouches(touches);
    } catch (const io::InputError& error) {
        std::fprintf(stderr, "everytouch-eval: %s\n", error.what());
        return kExitBadInput;
    } catch (const std::exception& error) {
        std::fprintf(stderr, "everytouch-eval: %s\n", error.what());
        return kExitFailure;
    }
    return kExitFailure;
}
