// ThreadSanitizer cannot see Debian's absl::Mutex: libabsl_synchronization.so
// is not built with TSan and its Mutex is a futex with atomics of its own, so
// every hand-over through an absl::Mutex (ours, and gRPC's grpc_core::Mutex
// which wraps it) would look like a data race. scripts/sanitize.sh preloads
// this library into every process of its TSan step: it interposes the Mutex
// and CondVar entry points, calls the real ones, and tells TSan that locking
// acquires and unlocking releases the mutex (__tsan_acquire/__tsan_release),
// which is the happens-before edge TSan would record for an instrumented mutex.
//
// The mangled names carry Debian 12's inline namespace (absl::debian3); the
// library refuses to start rather than silently do nothing if one is missing.
#include <dlfcn.h>
#include <sanitizer/tsan_interface.h>

#include <cstdio>
#include <cstdlib>

#include "absl/synchronization/mutex.h"

namespace {

template <typename F>
F Real(const char* mangled) {
  void* f = dlsym(RTLD_NEXT, mangled);
  if (f == nullptr) {
    std::fprintf(stderr, "absl_mutex_tsan: %s not found: %s\n", mangled, dlerror());
    std::abort();
  }
  return reinterpret_cast<F>(f);
}

#define MESHSEEK_REAL(name, type, mangled)      \
  static const auto name = Real<type>(mangled)

// Abseil evaluates a waiter's condition under the lock, either in the waiter
// or in the thread that unlocks; each evaluation is a critical section of
// its own, so the condition is wrapped to acquire and release around it.
struct AnnotatedCondition {
  const absl::Condition* condition;
  absl::Mutex* mutex;
  static bool Eval(AnnotatedCondition* c) {
    __tsan_acquire(c->mutex);
    const bool met = c->condition->Eval();
    __tsan_release(c->mutex);
    return met;
  }
};

}  // namespace

namespace absl {
ABSL_NAMESPACE_BEGIN

void Mutex::Lock() {
  MESHSEEK_REAL(real, void (*)(Mutex*), "_ZN4absl7debian35Mutex4LockEv");
  real(this);
  __tsan_acquire(this);
}
void Mutex::ReaderLock() {
  MESHSEEK_REAL(real, void (*)(Mutex*), "_ZN4absl7debian35Mutex10ReaderLockEv");
  real(this);
  __tsan_acquire(this);
}
bool Mutex::TryLock() {
  MESHSEEK_REAL(real, bool (*)(Mutex*), "_ZN4absl7debian35Mutex7TryLockEv");
  const bool locked = real(this);
  if (locked) __tsan_acquire(this);
  return locked;
}
bool Mutex::ReaderTryLock() {
  MESHSEEK_REAL(real, bool (*)(Mutex*), "_ZN4absl7debian35Mutex13ReaderTryLockEv");
  const bool locked = real(this);
  if (locked) __tsan_acquire(this);
  return locked;
}
void Mutex::Unlock() {
  MESHSEEK_REAL(real, void (*)(Mutex*), "_ZN4absl7debian35Mutex6UnlockEv");
  __tsan_release(this);
  real(this);
}
void Mutex::ReaderUnlock() {
  MESHSEEK_REAL(real, void (*)(Mutex*), "_ZN4absl7debian35Mutex12ReaderUnlockEv");
  __tsan_release(this);
  real(this);
}

// The conditional forms pass the annotated condition to the real call.
#define MESHSEEK_ANNOTATED(cond)             \
  AnnotatedCondition annotated{&(cond), this}; \
  const Condition wrapped(&AnnotatedCondition::Eval, &annotated)
void Mutex::LockWhen(const Condition& cond) {
  MESHSEEK_REAL(real, void (*)(Mutex*, const Condition&),
                "_ZN4absl7debian35Mutex8LockWhenERKNS0_9ConditionE");
  MESHSEEK_ANNOTATED(cond);
  real(this, wrapped);
  __tsan_acquire(this);
}
void Mutex::ReaderLockWhen(const Condition& cond) {
  MESHSEEK_REAL(real, void (*)(Mutex*, const Condition&),
                "_ZN4absl7debian35Mutex14ReaderLockWhenERKNS0_9ConditionE");
  MESHSEEK_ANNOTATED(cond);
  real(this, wrapped);
  __tsan_acquire(this);
}
bool Mutex::LockWhenWithTimeout(const Condition& cond, absl::Duration timeout) {
  MESHSEEK_REAL(real, bool (*)(Mutex*, const Condition&, absl::Duration),
                "_ZN4absl7debian35Mutex19LockWhenWithTimeoutERKNS0_9ConditionENS0_8DurationE");
  MESHSEEK_ANNOTATED(cond);
  const bool met = real(this, wrapped, timeout);
  __tsan_acquire(this);
  return met;
}
bool Mutex::LockWhenWithDeadline(const Condition& cond, absl::Time deadline) {
  MESHSEEK_REAL(real, bool (*)(Mutex*, const Condition&, absl::Time),
                "_ZN4absl7debian35Mutex20LockWhenWithDeadlineERKNS0_9ConditionENS0_4TimeE");
  MESHSEEK_ANNOTATED(cond);
  const bool met = real(this, wrapped, deadline);
  __tsan_acquire(this);
  return met;
}
void Mutex::Await(const Condition& cond) {
  MESHSEEK_REAL(real, void (*)(Mutex*, const Condition&),
                "_ZN4absl7debian35Mutex5AwaitERKNS0_9ConditionE");
  MESHSEEK_ANNOTATED(cond);
  __tsan_release(this);
  real(this, wrapped);
  __tsan_acquire(this);
}
bool Mutex::AwaitWithTimeout(const Condition& cond, absl::Duration timeout) {
  MESHSEEK_REAL(real, bool (*)(Mutex*, const Condition&, absl::Duration),
                "_ZN4absl7debian35Mutex16AwaitWithTimeoutERKNS0_9ConditionENS0_8DurationE");
  MESHSEEK_ANNOTATED(cond);
  __tsan_release(this);
  const bool met = real(this, wrapped, timeout);
  __tsan_acquire(this);
  return met;
}
bool Mutex::AwaitWithDeadline(const Condition& cond, absl::Time deadline) {
  MESHSEEK_REAL(real, bool (*)(Mutex*, const Condition&, absl::Time),
                "_ZN4absl7debian35Mutex17AwaitWithDeadlineERKNS0_9ConditionENS0_4TimeE");
  MESHSEEK_ANNOTATED(cond);
  __tsan_release(this);
  const bool met = real(this, wrapped, deadline);
  __tsan_acquire(this);
  return met;
}

void CondVar::Wait(Mutex* mu) {
  MESHSEEK_REAL(real, void (*)(CondVar*, Mutex*), "_ZN4absl7debian37CondVar4WaitEPNS0_5MutexE");
  __tsan_release(mu);
  real(this, mu);
  __tsan_acquire(mu);
}
bool CondVar::WaitWithTimeout(Mutex* mu, absl::Duration timeout) {
  MESHSEEK_REAL(real, bool (*)(CondVar*, Mutex*, absl::Duration),
                "_ZN4absl7debian37CondVar15WaitWithTimeoutEPNS0_5MutexENS0_8DurationE");
  __tsan_release(mu);
  const bool timed_out = real(this, mu, timeout);
  __tsan_acquire(mu);
  return timed_out;
}
bool CondVar::WaitWithDeadline(Mutex* mu, absl::Time deadline) {
  MESHSEEK_REAL(real, bool (*)(CondVar*, Mutex*, absl::Time),
                "_ZN4absl7debian37CondVar16WaitWithDeadlineEPNS0_5MutexENS0_4TimeE");
  __tsan_release(mu);
  const bool timed_out = real(this, mu, deadline);
  __tsan_acquire(mu);
  return timed_out;
}

ABSL_NAMESPACE_END
}  // namespace absl
