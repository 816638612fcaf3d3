#pragma once
/// @file metrics_scraper.hpp
/// A Prometheus stand-in for benchmarks: GET http://127.0.0.1:<port>/metrics at a
/// fixed period on a thread of its own, one connection per scrape (as Prometheus
/// does after an idle keep-alive), recording each scrape's latency.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

namespace fieldbridge::bench {

struct ScrapeFigures {
    std::uint64_t ok = 0;           ///< answered 200 with a body
    std::uint64_t failed = 0;       ///< refused, timed out (2 s) or not 200
    std::size_t last_bytes = 0;     ///< size of the last answer
    std::vector<double> latency_us; ///< connect -> last byte, sorted by stop()
    std::string failure;            ///< the first failure, if any
};

class MetricsScraper {
public:
    MetricsScraper(std::uint16_t port, std::chrono::milliseconds period);
    ~MetricsScraper();
    MetricsScraper(const MetricsScraper&) = delete;
    MetricsScraper& operator=(const MetricsScraper&) = delete;

    /// Stops scraping (joins the thread) and returns what it saw.
    [[nodiscard]] ScrapeFigures stop();

private:
    void run();

    std::uint16_t port_;
    std::chrono::milliseconds period_;
    std::atomic<bool> stop_{false};
    ScrapeFigures figures_;
    std::thread thread_;
};

}  // namespace fieldbridge::bench
