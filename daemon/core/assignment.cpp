#include "core/assignment.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace everytouch::core {

void LinearAssignment::reserve(int rows, int columns) {
    const auto small = static_cast<std::size_t>(std::min(rows, columns)) + 1;
    const auto large = static_cast<std::size_t>(std::max(rows, columns)) + 1;
    rowPotential_.reserve(small);
    columnPotential_.reserve(large);
    slack_.reserve(large);
    columnOwner_.reserve(large);
    predecessor_.reserve(large);
    visited_.reserve(large);
    transposed_.reserve(small);
}

double LinearAssignment::solve(int rows, int columns, std::span<const double> cost,
                               std::vector<int>& rowToColumn) {
    if (rows < 0 || columns < 0 || cost.size() != static_cast<std::size_t>(rows) * columns)
        throw std::invalid_argument("assignment: the cost matrix holds " + std::to_string(cost.size()) +
                                    " values, not " + std::to_string(rows) + " x " + std::to_string(columns));
    // An infinite or undefined cost would leave the search without a column to step to.
    const auto bad = std::find_if(cost.begin(), cost.end(), [](double c) { return !std::isfinite(c); });
    if (bad != cost.end()) {
        const auto index = static_cast<int>(bad - cost.begin());
        throw std::invalid_argument("assignment: the cost of row " + std::to_string(index / columns) +
                                    ", column " + std::to_string(index % columns) + " is not finite");
    }
    rowToColumn.assign(static_cast<std::size_t>(rows), -1);
    if (rows == 0 || columns == 0)
        return 0.0;
    if (rows <= columns) {
        solveWide(
            rows, columns, [&](int r, int c) { return cost[static_cast<std::size_t>(r) * columns + c]; },
            rowToColumn);
    } else {
        // Tall: every column gets a row, so solve with the roles swapped.
        solveWide(
            columns, rows, [&](int c, int r) { return cost[static_cast<std::size_t>(r) * columns + c]; },
            transposed_);
        for (int c = 0; c < columns; ++c)
            rowToColumn[transposed_[c]] = c;
    }
    double total = 0.0;
    for (int r = 0; r < rows; ++r)
        if (rowToColumn[r] >= 0)
            total += cost[static_cast<std::size_t>(r) * columns + rowToColumn[r]];
    return total;
}

// Rows are added one at a time. Each addition grows a tree of tight edges (zero reduced cost) from the new
// row by Dijkstra's rule over the reduced costs, shifting the potentials so that the tree's edges stay tight,
// until the tree reaches a free column; the path to it is then flipped. Reduced costs stay non-negative
// throughout, which is what makes every intermediate matching, and so the last, of least cost.
template <typename Cost>
void LinearAssignment::solveWide(int rows, int columns, Cost at, std::vector<int>& rowToColumn) {
    constexpr double kInfinity = std::numeric_limits<double>::infinity();
    const auto n = static_cast<std::size_t>(rows) + 1;
    const auto m = static_cast<std::size_t>(columns) + 1;
    rowPotential_.assign(n, 0.0);
    columnPotential_.assign(m, 0.0);
    columnOwner_.assign(m, 0);
    predecessor_.assign(m, 0);
    for (int row = 1; row <= rows; ++row) {
        columnOwner_[0] = row;
        int column = 0;
        slack_.assign(m, kInfinity);
        visited_.assign(m, 0);
        do {
            visited_[column] = 1;
            const int owner = columnOwner_[column];
            double delta = kInfinity;
            int next = 0;
            for (int j = 1; j <= columns; ++j) {
                if (visited_[j])
                    continue;
                const double reduced = at(owner - 1, j - 1) - rowPotential_[owner] - columnPotential_[j];
                if (reduced < slack_[j]) {
                    slack_[j] = reduced;
                    predecessor_[j] = column;
                }
                if (slack_[j] < delta) {
                    delta = slack_[j];
                    next = j;
                }
            }
            for (int j = 0; j <= columns; ++j) {
                if (visited_[j]) {
                    rowPotential_[columnOwner_[j]] += delta;
                    columnPotential_[j] -= delta;
                } else {
                    slack_[j] -= delta;
                }
            }
            column = next;
        } while (columnOwner_[column] != 0);
        do {
            const int previous = predecessor_[column];
            columnOwner_[column] = columnOwner_[previous];
            column = previous;
        } while (column != 0);
    }
    rowToColumn.assign(static_cast<std::size_t>(rows), -1);
    for (int j = 1; j <= columns; ++j)
        if (columnOwner_[j] != 0)
            rowToColumn[columnOwner_[j] - 1] = j - 1;
}

}  // namespace everytouch::core
