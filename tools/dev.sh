#!/usr/bin/env bash
# The developer's entry point (README "Quick start"):
#   tools/dev.sh run [everytouchd options]   install what is missing, build, run the daemon on the simulated rig
#   tools/dev.sh test                          install what is missing, build, run the whole test suite
#   tools/dev.sh sanitize                      the test suite again, built with AddressSanitizer + UBSan
#   tools/dev.sh tsan                          the tests whose code runs on several threads, with ThreadSanitizer
#   tools/dev.sh fuzz [SECONDS [TARGET...]]    fuzz each reader of outside input with libFuzzer (docs/fuzzing.md)
#   tools/dev.sh format                        apply clang-format to every C++ file (format-check: only report)
set -euo pipefail
cd "$(dirname "$0")/.."

# Debian 12 packages the build, the tests and the VM harness need.
packages=(
    build-essential cmake pkg-config clang-format lld
    libopencv-dev libeigen3-dev libgtest-dev libgmock-dev libbenchmark-dev
    libevdev-dev libsystemd-dev libaravis-dev libusb-1.0-0-dev aravis-tools libsdl2-dev xvfb
    libx11-dev libxext-dev libxfixes-dev libxrandr-dev libxpresent-dev libxtst-dev picom
    libwayland-dev wayland-protocols librust-wayland-protocols-dev sway swaybg grim wev
    libcli11-dev nlohmann-json3-dev libinih-dev scdoc mandoc lintian
    dbus systemd udev
    qemu-system-x86 busybox-static libinput-tools evemu-tools cpio xz-utils
    python3
)

jobs=$(nproc)

install_missing_packages() {
    local missing=()
    for package in "${packages[@]}"; do
        dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed" || missing+=("$package")
    done
    [ ${#missing[@]} -eq 0 ] && return
    echo "Installing ${missing[*]}"
    local sudo=()
    [ "$(id -u)" -eq 0 ] || sudo=(sudo)
    "${sudo[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# build DIR [cmake options...]
build() {
    local dir=$1
    shift
    local werror=OFF unity=OFF ci_flags=()
    # CI builds from scratch: a unity build (sixteen sources a compiler run) parses OpenCV's, Eigen's and
    # GoogleTest's headers a sixteenth as often, and line tables (-g1) instead of full debug information still
    # name file and line in every failure and report. Sixteen instead of eight took the normal build from
    # 462 s to 354 s on 2 cores; the sanitizer build, at -O1, took 539 and 448 s in two
    # runs against 517 s, within the runs' spread. A developer's build keeps one source a run, so that a
    # change recompiles one file and each file is checked to include what it uses, and full debug information.
    if [ "${CI:-}" = "true" ]; then
        werror=ON
        unity=ON
        ci_flags=(-DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG")
    fi
    # LLVM's linker: a test binary links in 0.5 s instead of GNU ld's 2.7 s, some thirty links a CI run.
    cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEVERYTOUCH_WERROR="$werror" \
        -DCMAKE_UNITY_BUILD="$unity" -DCMAKE_UNITY_BUILD_BATCH_SIZE=16 -DCMAKE_EXE_LINKER_FLAGS=-fuse-ld=lld \
        "${ci_flags[@]}" "$@" >/dev/null
    cmake --build "$dir" -j "$jobs"
}

cpp_files() { git ls-files --cached --others --exclude-standard '*.cpp' '*.h'; }

command=${1:-}
[ $# -gt 0 ] && shift
case "$command" in
run)
    install_missing_packages
    build build
    exec build/daemon/everytouchd --rig sim:demo --fast --log touches.jsonl "$@"
    ;;
test)
    install_missing_packages
    build build
    ctest --test-dir build --output-on-failure -j "$jobs" "$@"
    ;;
sanitize)
    install_missing_packages
    # Warnings are enforced by the normal build; GCC's flow analysis under ASan reports false positives.
    # -O1 -g1 keeps file:line in every report and halves the compile time of -O2 -g under ASan. The test
    # cases at -O0 compiled in half the time but ran the simulator's tests 3-9 times slower (Eigen inlined
    # into them): the whole run took 3.5 minutes longer.
    # The benchmarks and the developers' tools run no test: the normal build compiles them.
    # Always a unity build: 318 s from scratch on 2 cores instead of 523 s.
    build build-sanitize -DEVERYTOUCH_SANITIZE=ON -DEVERYTOUCH_BUILD_BENCHMARKS=OFF \
        -DEVERYTOUCH_BUILD_DEVELOPER_TOOLS=OFF -DEVERYTOUCH_WERROR=OFF -DCMAKE_UNITY_BUILD=ON \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
    # Left out under the sanitizers: tests that render hundreds of frames to measure what the normal build
    # measures, while the same code runs under the sanitizers on fewer frames in other tests. Each of these took
    # 20 s to minutes under ASan on 2 cores; with them the sanitizer run took 15 minutes, CI over 40.
    sanitizer_skips=(
        # A new user's "calibrate full" (some 2200 frames, 278 s under ASan) and the projector step end to end
        # (some 500): the steps run through ProjectorStep.*, TableSetUpStep.* and the table calibration.
        'ServiceTest\.ProjectorCalibrationOnTheSimulatedRig.*'
        'ServiceTest\.ANewUserCalibratesFully.*'
        # The calibration scenarios and rendered poses (25-30 s each): the same solvers run in the unit tests.
        'PairCalibrationScenario\.ChessboardAndStripeOnEveryBoardPose.*'
        'PairCalibrationScenario\.HoldsSevenStillScenes.*'
        'PairCalibrationScenario\.PosesAreWhatTheCalibration.*'
        'PairCalibrationScenario\.TheUserBeginsWhen.*'
        'NoiseFreeAndNoisy/RenderedPoses\..*'
        'ProjectorStep\.CalibratesThePairFromTheTableAndFiveTiltsTakenByThemselves'
        'Simulator\.MovingHandsAreBlurredOverTheExposureStillOnesAreNot'
        # Detection's accuracy over a hundred rendered frames or more: the pipeline's other tests run the code.
        'Fingertips\.FindTheSimulatedFingersAndTheirPads'
        'HandSegmentation\.TouchingFingertipsKeepTheirEnds'
        'HandSegmentation\.AFingerSlidingFlatOnTheTableKeepsItsWidth'
        'HandSegmentation\.AFingerPassingHighIsFoundInEveryPair'
        'HandSegmentation\.AnEmptyTableTheCalibrationPutsALittleOffStaysTable'
        'SurfaceHeightRendered\.ASlidingFingertipsHeightIsReadAndKeepsToItsSurface'
        'SurfaceHeightRendered\.AFingertipSeenFromAboveIsReadThroughItsShape'
        'TouchPipelineRendered\.ADragStaysOneTouch'
        'TouchPipelineRendered\.OnlyAStillSceneKeepsItsMask'
        'TouchPipelineRendered\.AFingerRestingOnTheTableIsNotLostToOnePairsSegmentation'
        # The calibration's check and correction: the knock left uncorrected (the same frames and code as the
        # corrected knock's case), the pipeline's correction and its hold on touches (the daemon's knocked
        # camera runs both, through the daemon), and the readings of a calibration that holds, measured in the normal build (7-15 s each).
        'TouchPipelineRendered\.WithoutTheCorrectionAKnockedCameraStaysMisregistered'
        'TouchPipelineRendered\.AKnockedCameraIsSeenWithinHalfASecondAndCorrected'
        'TouchPipelineRendered\.AKnockedCamerasTableIsNotTakenForFingersBeforeTheCorrection'
        'RegistrationCheck\.ACalibrationThatHoldsShowsAFewHundredthsOfAPixel'
        'CalibrationCorrector\.LeavesACalibrationThatHoldsAsItIs'
        # The check passing over the hand's tiles, the corrector's refusal and watch, the relocation's refusal
        # (8-10 s each): the same code runs under the sanitizers in the knocked camera's cases.
        'RegistrationCheck\.PassesOverTilesTheHandCovers'
        'CalibrationCorrector\.RefusesAMisregistrationNoMoveOfTheCameraExplains'
        'CalibrationCorrector\.WatchesWithoutAProblemWhatAMoveExplainsButNotYetBeyondTheNoise'
        'CameraRelocation\.RefusesTooFewTilesOrTilesInOneCorner'
        # The default pattern's windows checked over the whole panel (12 s): the pattern is made under the
        # sanitizers by every simulated rig.
        'Pattern\.DefaultPatternHasUniqueWindowsAndAHigherMinimumDistanceThanPlainRandom'
        'ServiceTest\.CalibrationErrorIsAFractionOfAPixelWhileTheCalibrationHolds'
        # The correction switched off by the configuration: its key is read in Config's unit tests, and the
        # daemon then runs the knocked rig's code without the correction.
        'ServiceTest\.WithTheCorrectionSwitchedOffAKnockedCameraIsShownAndLeftAsItIs'
        # The daemon on a tilted table (the knocked camera's case runs the daemon's adoption of a correction, and
        # CalibrationCorrector's the table's fit, under the sanitizers).
        'ServiceTest\.ATableTiltedAfterTheCalibrationIsCorrectedAsItsPlaneAndSaved'
        'HandSegmentation\.ACameraFramedOnTheProjectionStillTellsTheTableFromTheHand'
        # The code's blur and the renderer's hand mask measured over many rendered frames (13-17 s each):
        # CodeBlur's and SimSource's other cases run the same code.
        'CodeBlur\.FollowsTheCamerasFocusInQuadrature'
        'CodeBlur\.SeesAProjectorOutOfFocus'
        'SimSource\.HandMaskIsTheRenderersAndCoversTheTouchingFingers'
        # everytouch-eval on recordings of 64 and 240 frames, each recorded again by each case (11-84 s): the
        # scoring's unit tests (tests/unit/eval) and the cases without a recording run under the sanitizers.
        'EvaluateTouches\..*'
        'EvaluateSegmentation\.ScoresEveryMethodInATableAndInJson'
        'EvaluateSegmentation\.ScoresTheChosenMethodsOnly'
        'EvaluateSegmentation\.RefusesARecordingWithoutMasksNamingThem'
        # Frames whose polarity comes the other way round: 82 frames, 20 s each under ASan, twice, and the
        # daemon's replay of them. The frames' order is checked on three (PolarityLockTest).
        'TouchPipelinePolarity\..*' 'Everytouchd\.FramesLabelledTheOtherWayRoundGiveTheSameTouches'
        # The daemon judges a stall against the camera's own pace, which the sanitizers slow several times: the
        # frame loop's stall test (FrameLoopTest) and the pipeline's frames of another size run instead.
        'ServiceTest\.ACameraThatStallsOrChangesItsFramesSizeReleasesEveryContactUntilItsFramesFitAgain'
        # Waits of the daemon's own pace and of the table's set-up step, run again on code that other cases
        # run under the sanitizers (12-27 s each): the monitor's lines (TheMonitorEnds..., TheMonitorSays...),
        # a calibration refused while one runs (AClientThatFloodsCalibrate...), the set-up step waiting for the
        # board (RecoversTheTableAndFitsTheDisplay), a recording without a hand scored (the scoring's units).
        'ServiceTest\.TheMonitorShowsEachChangeOfContactsAsTheDaemonTracksThem'
        'ServiceTest\.ASecondCalibrationWhileOneRunsIsBusy'
        'TableSetUpStep\.AfterAnotherStepWaitsUntilTheBoardIsTakenAway'
        'TableSetUpStep\.AfterAnotherStepTakesABoardGoneBeforeItBegan'
        'EverytouchEval\.ARecordingWithoutAHandIsScoredNotRefused'
        # The fake GigE camera rendering the simulated rig on its thread (minutes under ASan, the camera lost
        # meanwhile): the GigE path runs in the camera's other tests, detection in the pipeline's, the overlay in
        # display_tests and AnOverlayNeedsAMonitorThatExistsAndACompositingManager. The projector window: SDL2
        # unloads at its end the libraries it loaded, and LeakSanitizer reports what they keep in frames it
        # cannot name; the window runs under the sanitizers in display_tests, without the leak check
        # (tests/CMakeLists.txt).
        'CameraServiceTest\.DetectsTheSimulatedRigsTapThroughGigEVision'
        'CameraServiceTest\.CalibratesTheTableThroughItsProjectorWindow'
        'CameraServiceTest\.CalibratesTheTableThroughItsOverlayAndMapsTheDisplayOntoTheWholeOutput'
        'CameraServiceTest\.TheAccuracyTestsCirclesShowInTheProjectorWindowWhileItsClientRuns'
        'CameraServiceTest\.ItsProjectorWindowShowsTheCodeAndTheCalibrationsChessboard'
        'CameraServiceTest\.AProjectorWindowOnADisplayThatDoesNotExistIsABadConfiguration'
        # Measurements the normal build makes (9-11 s each): no allocation per pair over rendered pairs (the
        # pipeline runs under the sanitizers in its own cases), the bit error rate over delta and noise, and
        # a recording's segmentation scored pair by pair (the scoring's units run).
        'SteadyStateAllocation\.ThePipelineAllocatesNothingPerPairOnceWarm'
        'SteadyStateAllocation\.AStillSceneAllocatesNothingEither'
        'Decoding\.BitErrorRateFallsWithDeltaAndRisesWithNoise'
        'EvaluateSegmentation\.ScoresEveryPairAndTheFingertipsOnEachMask'
        # The installed files' checks run systemd-analyze, cmake --install, cpack, lintian and mandoc, none of
        # our code.
        'SystemFiles\.TheUnitVerifies'
        'SystemFiles\.TheUnitStaysHardened'
        'SystemFiles\.EveryFileIsInstalledWhereTheSystemLooksForItWhateverThePrefix'
        'SystemFiles\.TheDebianPackageHoldsTheInstallAndLintianFindsNoError'
        'SystemFiles\.TheManualPagesHaveNoMandocWarning'
    )
    # ctest's regular expressions (CMake's, Henry Spencer's) hold at most nine groups, and one with more
    # matches nothing: one plain name an entry. Each entry must name a test (a renamed test would otherwise
    # run again unnoticed), and the joined list must leave out at least as many tests as it has entries.
    count_tests() { ctest --test-dir build-sanitize -N "$@" | sed -n 's/^Total Tests: //p'; }
    for skip in "${sanitizer_skips[@]}"; do
        if [ "$(count_tests -R "^($skip)$")" -eq 0 ]; then
            echo "sanitize: the skip list's entry $skip names no test" >&2
            exit 1
        fi
    done
    skips=$(IFS='|'; echo "${sanitizer_skips[*]}")
    left_out=$(($(count_tests) - $(count_tests -E "^($skips)$")))
    if [ "$left_out" -lt ${#sanitizer_skips[@]} ]; then
        echo "sanitize: the skip list has ${#sanitizer_skips[@]} entries but leaves out $left_out tests" >&2
        exit 1
    fi
    ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
        ctest --test-dir build-sanitize --output-on-failure -j "$jobs" -E "^($skips)$" "$@"
    ;;
tsan)
    install_missing_packages
    # The tests that run our code on several threads: the frame loop and what hands results between its
    # threads and the main loop, the recording's encoders and writer, the calibration job, the cameras'
    # sources, the projector window and the overlays and every test of the daemon binary. GLib, Aravis, GDAL, Mesa
    # and OpenCV are not built with ThreadSanitizer; tests/tsan-suppressions.txt names the reports it makes of their own
    # synchronisation. A new user's "calibrate full" renders some 2200 frames, over 300 s under
    # ThreadSanitizer; the projector step end to end runs the same code on fewer. The table
    # calibrated through the projector window or the overlay, and the accuracy test's circles filmed in the
    # window, render the simulated rig on the fake camera's thread, too slowly under ThreadSanitizer for the
    # daemon to see frames; the window's and the overlay's threads run in display_tests and in the daemon's
    # other window and overlay tests. The fake camera of the AravisSource tests that stream at 60 frames/s
    # pauses beyond the 0.3 s a camera may pause under ThreadSanitizer, even alone, and counts as lost; the
    # daemon's tests stream from it at 20 frames/s.
    build build-tsan -DEVERYTOUCH_THREAD_SANITIZER=ON -DEVERYTOUCH_BUILD_BENCHMARKS=OFF \
        -DEVERYTOUCH_BUILD_DEVELOPER_TOOLS=OFF -DEVERYTOUCH_WERROR=OFF -DCMAKE_UNITY_BUILD=ON \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG"
    TSAN_OPTIONS="suppressions=$PWD/tests/tsan-suppressions.txt halt_on_error=1" \
        ctest --test-dir build-tsan --output-on-failure -j "$jobs" \
        -R '^(FrameLoop|FrameQueue|FrameTap|RecordingThread|CalibrationJob|CalibrationRunner|SnapshotRequests|ArrivalRate|ServiceTest|DaemonOwnChecksTest|CameraServiceTest|AravisSource|WindowProjector|OverlayProjector|WaylandOverlayProjector|Everytouchd|EverytouchdConfig|EverytouchdService)' \
        -E '^(ServiceTest\.ANewUserCalibratesFully|CameraServiceTest\.(CalibratesTheTableThrough|TheAccuracyTestsCircles)|AravisSource\.(Delivers|ReadsColour|ACameraThatGoesAway))' "$@"
    ;;
fuzz)
    # clang only for this command: the test suite replays the corpora in every build without it. Its
    # libFuzzer and sanitizer runtimes come with libclang-rt-dev, which clang only recommends.
    packages+=(clang libclang-rt-dev)
    install_missing_packages
    seconds=${1:-600}
    [ $# -gt 0 ] && shift
    targets=("$@")
    [ ${#targets[@]} -gt 0 ] || targets=($(sed -n 's/^set(fuzz_targets \(.*\))$/\1/p' tests/fuzz/CMakeLists.txt))
    CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DEVERYTOUCH_FUZZ=ON \
        -DEVERYTOUCH_BUILD_BENCHMARKS=OFF -DEVERYTOUCH_BUILD_DEVELOPER_TOOLS=OFF -DCMAKE_UNITY_BUILD=ON \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" >/dev/null
    cmake --build build-fuzz -j "$jobs" --target "${targets[@]/#/fuzz_}"
    for target in "${targets[@]}"; do
        # New inputs go to build-fuzz/corpus/TARGET, findings to build-fuzz/findings/TARGET; the seeds in
        # tests/fuzz/corpus/TARGET are read, never written.
        mkdir -p "build-fuzz/corpus/$target" "build-fuzz/findings/$target"
        echo "fuzzing $target for $seconds s"
        # The file readers write every input to a scratch file first: in memory (/dev/shm) they run three
        # to four times as many inputs a second as on a disk's /tmp.
        TMPDIR=$( [ -d /dev/shm ] && [ -w /dev/shm ] && echo /dev/shm || echo "${TMPDIR:-/tmp}" ) \
            "build-fuzz/tests/fuzz/fuzz_$target" -max_total_time="$seconds" -timeout=1 -rss_limit_mb=2048 \
            -print_final_stats=1 -artifact_prefix="build-fuzz/findings/$target/" \
            "build-fuzz/corpus/$target" "tests/fuzz/corpus/$target"
    done
    ;;
format)
    cpp_files | xargs clang-format -i
    ;;
format-check)
    cpp_files | xargs clang-format --dry-run -Werror
    ;;
*)
    sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
    exit 2
    ;;
esac
