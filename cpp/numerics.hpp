// Shared numerics of the library: constants, quadrature rules and a
// parallel-for, in one place (the table builders, the display stage, the CPU
// backend and the tests use these, not copies).
#pragma once

#include <algorithm>
#include <atomic>
#include <cmath>
#include <thread>
#include <vector>

namespace airlight::numerics {

constexpr double kPi = 3.14159265358979323846;
constexpr double kEulerGamma = 0.57721566490153286061;

// 8-point Gauss-Legendre rule on [-1, 1]: nodes and weights.
constexpr double kGaussLegendre8Nodes[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                            -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                            0.7966664774136267,  0.9602898564975363};
constexpr double kGaussLegendre8Weights[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                              0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                              0.2223810344533745, 0.1012285362903763};

// The Henyey-Greenstein phase function (normalised over the sphere) at the cosine mu between the
// light's directions of travel before and after scattering.
inline double henyey_greenstein(double g, double mu) {
    const double den = 1.0 + g * g - 2.0 * g * mu;
    return (1.0 - g * g) / (4.0 * kPi * den * std::sqrt(den));
}

// A fractional node index x on a grid of n >= 2 nodes: the lower node (clamped to [0, n - 2]) and the
// fraction toward the next, for linear interpolation.
inline void node_and_fraction(double x, int n, int& node, double& frac) {
    x = std::clamp(x, 0.0, double(n - 1));
    node = std::min(int(x), n - 2);
    frac = x - node;
}

// The number of threads a pool uses: `requested` when > 0, else the machine's cores.
inline int thread_count(int requested = 0) {
    return requested > 0 ? requested : int(std::max(1u, std::thread::hardware_concurrency()));
}

// The number of workers the pools below use for n items: min(n, thread_count(threads)), at least 1.
inline int worker_count(int n, int threads = 0) { return std::max(1, std::min(n, thread_count(threads))); }

// Runs body(i, worker) for every i in [0, n) on worker_count(n, threads) threads (the calling thread is
// worker 0), handing out indices one at a time (dynamically: which worker gets which index varies from run
// to run). worker in [0, worker_count(n, threads)) says which thread runs it, for per-worker scratch or
// partial sums; a result summed per worker then depends on the schedule unless the sums are exact.
template <class Body>
void parallel_for_worker(int n, const Body& body, int threads = 0) {
    std::atomic<int> next{0};
    auto worker = [&](int w) {
        for (int i = next++; i < n; i = next++) body(i, w);
    };
    const int count = worker_count(n, threads);
    std::vector<std::thread> pool;
    for (int w = 1; w < count; ++w) pool.emplace_back(worker, w);
    worker(0);
    for (std::thread& th : pool) th.join();
}

// Runs body(i) for every i in [0, n) on min(n, thread_count(threads)) threads
// (the calling thread among them), handing out indices one at a time.
template <class Body>
void parallel_for(int n, const Body& body, int threads = 0) {
    const auto indexed = [&body](int i, int) { body(i); };
    parallel_for_worker(n, indexed, threads);
}

// Runs body(begin, end) over [0, n) split statically into k = worker_count(n, threads) contiguous chunks,
// one per thread (the calling thread takes the first): chunk t is [n t / k, n (t + 1) / k). Which indices
// share a chunk depends only on n and k, never on the schedule. Nothing runs when n <= 0.
template <class Body>
void parallel_for_chunks(int n, const Body& body, int threads = 0) {
    if (n <= 0) return;
    const int k = worker_count(n, threads);
    auto bound = [n, k](int t) { return static_cast<int>(static_cast<long long>(n) * t / k); };
    std::vector<std::thread> pool;
    for (int t = 1; t < k; ++t) pool.emplace_back([&body, &bound, t] { body(bound(t), bound(t + 1)); });
    body(0, bound(1));
    for (std::thread& th : pool) th.join();
}

}  // namespace airlight::numerics
