// Runs the real everytouch-eval on recordings the real everytouchd makes of the simulated rig.
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "io/recording.h"
#include "support/file_contents.h"
#include "support/process.h"
#include "support/temp_dir.h"
#include "support/test_rig.h"

namespace everytouch {
namespace {

using ::testing::HasSubstr;

// A number in [0, 1]; fails the test otherwise.
void expectFraction(const nlohmann::json& value, const std::string& what) {
    ASSERT_TRUE(value.is_number()) << what << ": " << value.dump();
    EXPECT_GE(value.get<double>(), 0.0) << what;
    EXPECT_LE(value.get<double>(), 1.0) << what;
}

class EvaluateSegmentation : public ::testing::Test {
protected:
    // One recording for the suite: 64 frames of the grid35 session from 0.25 s on, in which the hand comes in
    // after the first 30 frames, BkSub's background.
    static void SetUpTestSuite() {
        directory_ = new test::TempDir;
        const test::ProcessResult result =
            test::runProcess({EVERYTOUCHD_PATH, "--rig", "sim:grid35,seed=4,start=0.25", "--fast", "--frames",
                              "64", "--record", recording().string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
    }
    static void TearDownTestSuite() {
        delete directory_;
        directory_ = nullptr;
    }
    static std::filesystem::path recording() { return *directory_ / "grid35"; }
    static std::filesystem::path scratch(const std::string& name) { return *directory_ / name; }

    static test::TempDir* directory_;
};

test::TempDir* EvaluateSegmentation::directory_ = nullptr;

TEST_F(EvaluateSegmentation, ScoresEveryMethodInATableAndInJson) {
    const std::filesystem::path json = scratch("scores.json"), sheet = scratch("sheet.png");
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "segmentation", recording().string(), "--json", json.string(),
                          "--png", sheet.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out, HasSubstr("63 pairs"));
    EXPECT_THAT(result.out, HasSubstr("precision"));
    for (const char* row : {"\nours ", "\npaper ", "\nSCM ", "\nBkSub ", "\ntruth "})
        EXPECT_THAT(result.out, HasSubstr(row));

    const nlohmann::json scores = nlohmann::json::parse(test::fileContents(json));
    EXPECT_EQ(scores["pairs"], 63);
    EXPECT_GT(scores["pairs_with_hand"].get<int>(), 10);
    EXPECT_DOUBLE_EQ(scores["beta_squared"].get<double>(), 0.3);
    ASSERT_EQ(scores["methods"].size(), 4u);
    const char* names[] = {"ours", "paper", "SCM", "BkSub"};
    for (std::size_t m = 0; m < 4; ++m) {
        const nlohmann::json& method = scores["methods"][m];
        const std::string name = method["name"];
        EXPECT_EQ(name, names[m]);
        ASSERT_TRUE(method["available"].get<bool>()) << name;
        for (const char* field : {"precision", "recall", "f_beta"}) {
            expectFraction(method[field], name + " " + field);
            expectFraction(method["per_pair_mean"][field], name + " per-pair " + field);
            expectFraction(method["within_display"][field], name + " within the display " + field);
        }
        EXPECT_GT(method["pixels"]["true_positive"].get<long>(), 0) << name;
        EXPECT_GT(method["fingertips"]["truth_fingers"].get<long>(), 0) << name;
        expectFraction(method["fingertips"]["detection_rate"], name + " detection rate");
        EXPECT_FALSE(method["description"].get<std::string>().empty());
    }
    // Fingertips on the truth masks: the finder alone finds the pointing finger.
    const nlohmann::json& onTruth = scores["fingertips"]["on_truth_masks"];
    EXPECT_GT(onTruth["detection_rate"].get<double>(), 0.5);
    EXPECT_LT(onTruth["mean_error_px"].get<double>(),
              scores["fingertips"]["finger_width_px_at_display_centre"]);

    // The baselines are what they are known to be: BkSub misses little of a hand, SCM marks some of the
    // content too.
    EXPECT_GT(scores["methods"][3]["recall"].get<double>(), 0.9);
    EXPECT_GT(scores["methods"][2]["pixels"]["false_positive"].get<long>(), 0);

    // The sheet: texture, truth and the four methods, half size.
    const cv::Mat picture = cv::imread(sheet.string());
    ASSERT_FALSE(picture.empty());
    EXPECT_GE(picture.cols, 6 * 324);
    EXPECT_LT(picture.cols, 7 * 324);
}

TEST_F(EvaluateSegmentation, ScoresTheChosenMethodsOnly) {
    const std::filesystem::path json = scratch("chosen.json");
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "segmentation", recording().string(), "--methods",
                          "BkSub,SCM", "--json", json.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json scores = nlohmann::json::parse(test::fileContents(json));
    ASSERT_EQ(scores["methods"].size(), 2u);
    EXPECT_EQ(scores["methods"][0]["name"], "BkSub");
    EXPECT_EQ(scores["methods"][1]["name"], "SCM");
    const test::ProcessResult unknown =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "segmentation", recording().string(), "--methods", "GB"});
    EXPECT_EQ(unknown.exitCode, 2);
    EXPECT_THAT(unknown.err, HasSubstr("--methods GB"));
}

TEST_F(EvaluateSegmentation, RefusesARecordingWithoutMasksNamingThem) {
    const std::filesystem::path bare = scratch("bare");
    io::RecordingWriter writer(bare, test::paperLikeRig(), false);
    for (std::uint64_t i = 0; i < 4; ++i) {
        core::Frame frame;
        frame.index = i;
        frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
        frame.image = cv::Mat(cv::Size(648, 488), CV_8UC3, cv::Scalar(128, 128, 128));
        writer.addFrame(frame);
    }
    writer.flush();
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "segmentation", bare.string()});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("masks/"));
    EXPECT_THAT(result.err, HasSubstr(bare.string()));
}

TEST(EverytouchEval, ARecordingWithoutAHandIsScoredNotRefused) {
    test::TempDir directory;
    const std::filesystem::path recording = directory / "idle", json = directory / "idle.json";
    const test::ProcessResult record = test::runProcess(
        {EVERYTOUCHD_PATH, "--rig", "sim:idle", "--fast", "--frames", "12", "--record", recording.string()});
    ASSERT_EQ(record.exitCode, 0) << record.err;
    // A short background: four pairs sharing no frame span the first eight frames.
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "segmentation", recording.string(), "--background-pairs", "4",
                          "--json", json.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    const nlohmann::json scores = nlohmann::json::parse(test::fileContents(json));
    EXPECT_EQ(scores["pairs"], 11);
    EXPECT_EQ(scores["pairs_with_hand"], 0);
    ASSERT_EQ(scores["methods"].size(), 4u);
    for (const nlohmann::json& method : scores["methods"]) {
        ASSERT_TRUE(method["available"].get<bool>()) << method["name"];
        EXPECT_TRUE(method["recall"].is_null());
        EXPECT_TRUE(method["per_pair_mean"]["f_beta"].is_null());
        EXPECT_EQ(method["pixels"]["true_positive"], 0);
    }
}

class EvaluateTouches : public ::testing::Test {
protected:
    // Two seconds of the grid35 session: the hand comes in after 0.6 s and taps the first circle.
    static void SetUpTestSuite() {
        directory_ = new test::TempDir;
        const test::ProcessResult result =
            test::runProcess({EVERYTOUCHD_PATH, "--rig", "sim:grid35", "--fast", "--frames", "240",
                              "--record", recording().string()});
        ASSERT_EQ(result.exitCode, 0) << result.err;
    }
    static void TearDownTestSuite() {
        delete directory_;
        directory_ = nullptr;
    }
    static std::filesystem::path recording() { return *directory_ / "grid35"; }
    static std::filesystem::path scratch(const std::string& name) { return *directory_ / name; }

    // The table and the JSON of one run; fails the test unless it succeeds.
    static nlohmann::json score(const std::vector<std::string>& arguments,
                                const std::filesystem::path& json) {
        std::vector<std::string> command{EVERYTOUCH_EVAL_PATH, "touches", recording().string()};
        command.insert(command.end(), arguments.begin(), arguments.end());
        command.insert(command.end(), {"--json", json.string()});
        const test::ProcessResult result = test::runProcess(command);
        EXPECT_EQ(result.exitCode, 0) << result.err;
        for (const char* row : {"240 frames", "FRR", "FAR", "epsilon at touch-down", "latency", "id swaps",
                                "hover height error", "10-20 mm"})
            EXPECT_THAT(result.out, HasSubstr(row));
        return nlohmann::json::parse(test::fileContents(json));
    }

    static test::TempDir* directory_;
};

test::TempDir* EvaluateTouches::directory_ = nullptr;

TEST_F(EvaluateTouches, ScoresThePipelineAndItsTouchLogAlike) {
    const std::filesystem::path plot = scratch("touches.png");
    const nlohmann::json direct = score({"--png", plot.string()}, scratch("direct.json"));
    EXPECT_EQ(direct["frames"], 240);
    EXPECT_TRUE(direct["log"].is_null());
    EXPECT_DOUBLE_EQ(direct["match_radius_mm"].get<double>(), 8.0);
    EXPECT_GT(direct["match_radius_px"].get<double>(), 1.0);
    ASSERT_GE(direct["trials"].get<int>(), 1);
    expectFraction(direct["frr"], "FRR");
    EXPECT_GE(direct["far"].get<double>(), 0.0);
    EXPECT_EQ(direct["per_trial"].size(), direct["trials"].get<std::size_t>());
    for (const char* field : {"epsilon_touch_down_px", "epsilon_touching_px", "latency_frames",
                              "hover_error_mm", "drag_deviation_px"})
        EXPECT_TRUE(direct[field].contains("mean") && direct[field].contains("count")) << field;
    EXPECT_EQ(direct["hover_error_bands"].size(), 4u);
    EXPECT_GT(direct["hover_error_mm"]["count"].get<int>(), 0);
    const cv::Mat picture = cv::imread(plot.string());
    ASSERT_FALSE(picture.empty());

    // The daemon replaying the recording logs what the evaluator found running the pipeline itself.
    const std::filesystem::path log = scratch("touches.jsonl");
    const test::ProcessResult replay = test::runProcess(
        {EVERYTOUCHD_PATH, "--rig", "replay:" + recording().string(), "--fast", "--log", log.string()});
    ASSERT_EQ(replay.exitCode, 0) << replay.err;
    const nlohmann::json logged = score({log.string()}, scratch("logged.json"));
    EXPECT_EQ(logged["log"], log.string());
    EXPECT_EQ(logged["trials"], direct["trials"]);
    EXPECT_EQ(logged["touch_downs"], direct["touch_downs"]);
    EXPECT_EQ(logged["rejected"], direct["rejected"]);
}

TEST_F(EvaluateTouches, ScoresTheSimulatedRigLiveAsItsRecording) {
    const nlohmann::json recorded = score({}, scratch("recorded.json"));
    const std::filesystem::path json = scratch("live.json");
    const test::ProcessResult result = test::runProcess(
        {EVERYTOUCH_EVAL_PATH, "touches", "--rig", "sim:grid35", "--frames", "240", "--json", json.string()});
    ASSERT_EQ(result.exitCode, 0) << result.err;
    EXPECT_THAT(result.out, HasSubstr("sim:grid35: 240 frames"));
    const nlohmann::json live = nlohmann::json::parse(test::fileContents(json));
    for (const char* field : {"frames", "trials", "touch_downs", "rejected", "high_hover_touch_frames"})
        EXPECT_EQ(live[field], recorded[field]) << field;
    ASSERT_EQ(live["per_trial"].size(), recorded["per_trial"].size());
    for (std::size_t i = 0; i < live["per_trial"].size(); ++i) {
        const nlohmann::json &a = live["per_trial"][i], &b = recorded["per_trial"][i];
        for (const char* field : {"finger", "first", "last", "found", "latency_frames"})
            EXPECT_EQ(a[field], b[field]) << "trial " << i << " " << field;
        // truth.csv keeps a millimetre's thousandth of a display pixel; the rig itself keeps all digits.
        EXPECT_NEAR(a["error_px"].get<double>(), b["error_px"].get<double>(), 0.01) << "trial " << i;
    }
}

TEST(EverytouchEval, TouchesOnARigNeedsAnEndAndTheSimulatedRig) {
    const test::ProcessResult endless =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "touches", "--rig", "sim:grid35"});
    EXPECT_EQ(endless.exitCode, 2);
    EXPECT_THAT(endless.err, HasSubstr("--frames"));
    const test::ProcessResult replay =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "touches", "--rig", "replay:/nonexistent", "--frames", "9"});
    EXPECT_EQ(replay.exitCode, 2);
    EXPECT_THAT(replay.err, HasSubstr("only the simulated rig"));
    const test::ProcessResult neither = test::runProcess({EVERYTOUCH_EVAL_PATH, "touches"});
    EXPECT_EQ(neither.exitCode, 2);
    EXPECT_THAT(neither.err, HasSubstr("--rig"));
}

TEST_F(EvaluateTouches, RefusesALogOfAnotherRecordingNamingTheLine) {
    const std::filesystem::path log = scratch("foreign.jsonl");
    {
        std::ofstream out(log);
        out << R"({"index": 3, "t_us": 25000, "contacts": []})" << '\n'
            << R"({"index": 99999, "t_us": 900000, "contacts": []})" << '\n';
    }
    const test::ProcessResult result =
        test::runProcess({EVERYTOUCH_EVAL_PATH, "touches", recording().string(), log.string()});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("line 2"));
    EXPECT_THAT(result.err, HasSubstr("99999"));
}

TEST(EverytouchEval, TouchesRefusesARecordingWithoutTruth) {
    test::TempDir directory;
    const std::filesystem::path bare = directory / "bare";
    io::RecordingWriter writer(bare, test::paperLikeRig(), false);
    for (std::uint64_t i = 0; i < 4; ++i) {
        core::Frame frame;
        frame.index = i;
        frame.polarity = i % 2 ? core::Polarity::Negative : core::Polarity::Positive;
        frame.image = cv::Mat(cv::Size(648, 488), CV_8UC3, cv::Scalar(128, 128, 128));
        writer.addFrame(frame);
    }
    writer.flush();
    const test::ProcessResult result = test::runProcess({EVERYTOUCH_EVAL_PATH, "touches", bare.string()});
    EXPECT_EQ(result.exitCode, 2);
    EXPECT_THAT(result.err, HasSubstr("truth.csv"));
}

TEST(EverytouchEval, HelpNamesTheSubcommandsAndTheBaselinesDeviation) {
    const test::ProcessResult result = test::runProcess({EVERYTOUCH_EVAL_PATH, "segmentation", "--help"});
    EXPECT_EQ(result.exitCode, 0);
    for (const char* text : {"--json", "--png", "SCM", "BkSub", "Jones & Rehg", "median", "eq. 23"})
        EXPECT_THAT(result.out, HasSubstr(text));
    const test::ProcessResult top = test::runProcess({EVERYTOUCH_EVAL_PATH, "--help"});
    EXPECT_THAT(top.out, HasSubstr("segmentation"));
    EXPECT_THAT(top.out, HasSubstr("touches"));
    EXPECT_THAT(top.out, HasSubstr("Exit status"));
}

TEST(EverytouchEval, WithoutASubcommandIsAUsageError) {
    EXPECT_EQ(test::runProcess({EVERYTOUCH_EVAL_PATH}).exitCode, 2);
}

}  // namespace
}  // namespace everytouch
