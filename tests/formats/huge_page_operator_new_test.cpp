// The tools' operator new (formats/src/huge_page_operator_new.cpp), linked into this program as it
// is into `bake` and `exitance-relight`: an allocation of kHugePageAdvisedFrom bytes or more lies in
// a mapping the kernel was told to back with huge pages (its VmFlags in /proc/self/smaps carry
// "hg", MADV_HUGEPAGE), a smaller one does not, and what they hold is what was written.
#include <gtest/gtest.h>

#include <sys/mman.h>

#include <cstdint>
#include <fstream>
#include <memory>
#include <new>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

#include "exitance/formats/huge_page_operator_new.h"

namespace {

// The VmFlags of the mapping holding `address`, from /proc/self/smaps; empty when none is found.
std::string vm_flags_at(const void* address) {
  const uintptr_t a = reinterpret_cast<uintptr_t>(address);
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line)) {
    uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream range(line);
    if (range >> std::hex >> lo >> dash >> hi && dash == '-' && line.find(':') > line.find(' ')) {
      inside = a >= lo && a < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line.substr(8) + " ";
  }
  return {};
}

bool kernel_takes_huge_page_advice() {
  void* probe = mmap(nullptr, size_t(4) << 20, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (probe == MAP_FAILED) return false;
  const bool taken = madvise(probe, size_t(2) << 20, MADV_HUGEPAGE) == 0;
  munmap(probe, size_t(4) << 20);
  return taken;
}

TEST(HugePageOperatorNew, LargeAllocationsAreAdvisedAndSmallOnesAreNot) {
  if (!exitance::formats::kHugePageOperatorNew) GTEST_SKIP() << "a sanitizer's operator new is in use";
  if (!kernel_takes_huge_page_advice()) GTEST_SKIP() << "this kernel takes no MADV_HUGEPAGE advice";
  const size_t large = exitance::formats::kHugePageAdvisedFrom + (size_t(3) << 20);
  std::vector<uint32_t> big(large / sizeof(uint32_t));
  std::iota(big.begin(), big.end(), 0u);
  // A point past the first 2 MiB boundary inside the block lies in the advised range.
  const std::string big_flags = vm_flags_at(reinterpret_cast<const char*>(big.data()) + (size_t(3) << 20));
  ASSERT_FALSE(big_flags.empty());
  EXPECT_NE(big_flags.find(" hg "), std::string::npos) << big_flags;
  EXPECT_EQ(big[12345], 12345u);
  EXPECT_EQ(big.back(), uint32_t(big.size() - 1));

  // Under the threshold (but above malloc's mmap threshold, so in a mapping of its own): no advice.
  std::vector<uint8_t> small(exitance::formats::kHugePageAdvisedFrom - 4096, 7);
  const std::string small_flags = vm_flags_at(small.data() + small.size() / 2);
  ASSERT_FALSE(small_flags.empty());
  EXPECT_EQ(small_flags.find(" hg "), std::string::npos) << small_flags;
  EXPECT_EQ(small[100], 7);
}

TEST(HugePageOperatorNew, NothrowAndArrayFormsAllocate) {
  std::unique_ptr<char[]> array(new char[exitance::formats::kHugePageAdvisedFrom]);
  array[0] = 'a';
  array[exitance::formats::kHugePageAdvisedFrom - 1] = 'z';
  EXPECT_EQ(array[0], 'a');
  int* one = new (std::nothrow) int(42);
  ASSERT_NE(one, nullptr);
  EXPECT_EQ(*one, 42);
  delete one;
  void* none = ::operator new(0);  // a unique pointer, as the standard asks
  EXPECT_NE(none, nullptr);
  ::operator delete(none);
}

}  // namespace
