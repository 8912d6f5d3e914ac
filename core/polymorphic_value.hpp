#pragma once
// Owns an object of a class derived from T and copies it deeply (T::clone()), so that specs of
// many kinds can live in copyable scenes.
#include <memory>
#include <string>
#include <typeinfo>

#include <jelly/core/errors.hpp>

namespace jelly {

template <typename T>
class PolymorphicValue {
 public:
  PolymorphicValue() = default;
  PolymorphicValue(std::unique_ptr<T> p) : p_(std::move(p)) {}  // NOLINT: implicit on purpose
  template <typename U>
  PolymorphicValue(const U& value) : p_(std::make_unique<U>(value)) {}  // NOLINT
  PolymorphicValue(const PolymorphicValue& o) : p_(o.p_ ? o.p_->clone() : nullptr) {}
  PolymorphicValue(PolymorphicValue&&) noexcept = default;
  PolymorphicValue& operator=(const PolymorphicValue& o) {
    if (this != &o) p_ = o.p_ ? o.p_->clone() : nullptr;
    return *this;
  }
  PolymorphicValue& operator=(PolymorphicValue&&) noexcept = default;

  explicit operator bool() const { return p_ != nullptr; }
  T* get() { return p_.get(); }
  const T* get() const { return p_.get(); }
  T* operator->() { return p_.get(); }
  const T* operator->() const { return p_.get(); }
  T& operator*() { return *p_; }
  const T& operator*() const { return *p_; }

  // The object as its concrete class U; throws InputError when it is of another kind.
  template <typename U>
  U& as() {
    U* u = dynamic_cast<U*>(p_.get());
    if (u == nullptr) throw InputError("the spec is not a " + std::string(typeid(U).name()));
    return *u;
  }
  template <typename U>
  const U& as() const {
    return const_cast<PolymorphicValue*>(this)->as<U>();
  }
  template <typename U>
  bool is() const {
    return dynamic_cast<const U*>(p_.get()) != nullptr;
  }

 private:
  std::unique_ptr<T> p_;
};

}  // namespace jelly
