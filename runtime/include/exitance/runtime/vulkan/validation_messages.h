// Validation-layer messages turned into failures: messages arrive on a driver callback, are
// collected here, and the bake or relight that produced them fails afterwards.
#pragma once
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

namespace exitance {

class ValidationMessages {
 public:
  // For VulkanDeviceOptions::on_validation_message; keeps the collection alive while the device needs it.
  static std::function<void(const std::string&)> collector(const std::shared_ptr<ValidationMessages>& messages) {
    return [messages](const std::string& message) {
      std::lock_guard<std::mutex> lock(messages->mutex_);
      messages->lines_.push_back(message);
    };
  }

  // Throws std::runtime_error naming the count and the first message, if any arrived.
  void throw_if_any() const {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!lines_.empty())
      throw std::runtime_error("Vulkan validation reported " + std::to_string(lines_.size()) +
                               " messages, first: " + lines_.front());
  }

 private:
  mutable std::mutex mutex_;
  std::vector<std::string> lines_;
};

}  // namespace exitance
