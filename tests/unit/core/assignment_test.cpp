#include "core/assignment.h"

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

#include "support/allocation_counter.h"

namespace everytouch::core {
namespace {

// The least total cost over every way to pair min(rows, columns) rows with distinct columns.
double bruteForceCost(int rows, int columns, const std::vector<double>& cost) {
    if (rows == 0 || columns == 0)
        return 0.0;
    // Permute the longer side; the first `short` entries pair with the shorter side in order.
    const bool wide = rows <= columns;
    const int shortSide = std::min(rows, columns);
    std::vector<int> longSide(static_cast<std::size_t>(std::max(rows, columns)));
    std::iota(longSide.begin(), longSide.end(), 0);
    double best = std::numeric_limits<double>::infinity();
    do {
        double total = 0.0;
        for (int s = 0; s < shortSide; ++s) {
            const int r = wide ? s : longSide[s];
            const int c = wide ? longSide[s] : s;
            total += cost[static_cast<std::size_t>(r) * columns + c];
        }
        best = std::min(best, total);
    } while (std::next_permutation(longSide.begin(), longSide.end()));
    return best;
}

// Every row paired at most once with a distinct column, min(rows, columns) pairs; the total of those pairs.
double checkedTotal(int rows, int columns, const std::vector<double>& cost,
                    const std::vector<int>& rowToColumn) {
    EXPECT_EQ(rowToColumn.size(), static_cast<std::size_t>(rows));
    std::vector<int> used(static_cast<std::size_t>(columns), 0);
    int pairs = 0;
    double total = 0.0;
    for (int r = 0; r < rows; ++r) {
        const int c = rowToColumn[r];
        if (c < 0)
            continue;
        EXPECT_LT(c, columns);
        EXPECT_EQ(used[c]++, 0) << "column " << c << " taken twice";
        ++pairs;
        total += cost[static_cast<std::size_t>(r) * columns + c];
    }
    EXPECT_EQ(pairs, std::min(rows, columns));
    return total;
}

TEST(LinearAssignment, PicksTheCheapestPairingOverTheGreedyOne) {
    // Greedy would take (0, 0) at 1 and then be left with (1, 1) at 10; the optimum pairs across.
    const std::vector<double> cost = {1, 2,  //
                                      3, 10};
    LinearAssignment solver;
    std::vector<int> rowToColumn;
    EXPECT_DOUBLE_EQ(solver.solve(2, 2, cost, rowToColumn), 5.0);
    EXPECT_EQ(rowToColumn, (std::vector<int>{1, 0}));
}

TEST(LinearAssignment, MatchesBruteForceOnRandomMatrices) {
    std::mt19937 random(20240611);
    std::uniform_real_distribution<double> uniform(0.0, 100.0);
    std::uniform_int_distribution<int> small(0, 3);  // many ties
    LinearAssignment solver;
    std::vector<int> rowToColumn;
    for (int trial = 0; trial < 3000; ++trial) {
        const int rows = trial % 8;
        const int columns = (trial / 8) % 8;
        std::vector<double> cost(static_cast<std::size_t>(rows) * columns);
        const int kind = trial % 3;
        for (double& c : cost) {
            if (kind == 0)
                c = uniform(random);
            else if (kind == 1)
                c = small(random);
            else  // gated: forbidden pairs priced above all others together, as the tracker does
                c = uniform(random) < 40.0 ? 1e6 : uniform(random);
        }
        const double total = solver.solve(rows, columns, cost, rowToColumn);
        const double expected = bruteForceCost(rows, columns, cost);
        EXPECT_NEAR(total, expected, 1e-9 * std::max(1.0, expected))
            << rows << " x " << columns << ", trial " << trial;
        EXPECT_NEAR(checkedTotal(rows, columns, cost, rowToColumn), total, 1e-9 * std::max(1.0, total));
    }
}

TEST(LinearAssignment, NegativeCostsAreFine) {
    std::mt19937 random(7);
    std::uniform_real_distribution<double> uniform(-50.0, 50.0);
    LinearAssignment solver;
    std::vector<int> rowToColumn;
    for (int trial = 0; trial < 200; ++trial) {
        const int rows = 1 + trial % 6, columns = 1 + (trial / 6) % 6;
        std::vector<double> cost(static_cast<std::size_t>(rows) * columns);
        for (double& c : cost)
            c = uniform(random);
        EXPECT_NEAR(solver.solve(rows, columns, cost, rowToColumn), bruteForceCost(rows, columns, cost),
                    1e-9);
    }
}

TEST(LinearAssignment, AnEmptySideLeavesEveryRowUnpaired) {
    LinearAssignment solver;
    std::vector<int> rowToColumn;
    EXPECT_EQ(solver.solve(3, 0, {}, rowToColumn), 0.0);
    EXPECT_EQ(rowToColumn, (std::vector<int>{-1, -1, -1}));
    EXPECT_EQ(solver.solve(0, 4, {}, rowToColumn), 0.0);
    EXPECT_TRUE(rowToColumn.empty());
}

TEST(LinearAssignment, RejectsAWrongSizeOrANonFiniteCost) {
    LinearAssignment solver;
    std::vector<int> rowToColumn;
    EXPECT_THROW(solver.solve(2, 2, std::vector<double>{1, 2, 3}, rowToColumn), std::invalid_argument);
    const std::vector<double> infinite = {1, std::numeric_limits<double>::infinity(), 3, 4};
    try {
        solver.solve(2, 2, infinite, rowToColumn);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_STREQ(e.what(), "assignment: the cost of row 0, column 1 is not finite");
    }
}

TEST(LinearAssignment, AllocatesNothingWithinItsReservation) {
    LinearAssignment solver;
    solver.reserve(12, 12);
    std::vector<int> rowToColumn;
    rowToColumn.reserve(12);
    std::vector<double> cost(12 * 12);
    std::mt19937 random(3);
    std::uniform_real_distribution<double> uniform(0.0, 10.0);
    for (double& c : cost)
        c = uniform(random);
    const std::uint64_t before = test::allocationCount();
    for (int rows = 0; rows <= 12; ++rows)
        for (int columns = 0; columns <= 12; ++columns)
            solver.solve(rows, columns,
                         std::span<const double>(cost.data(), static_cast<std::size_t>(rows) * columns),
                         rowToColumn);
    EXPECT_EQ(test::allocationCount() - before, 0u);
}

}  // namespace
}  // namespace everytouch::core
