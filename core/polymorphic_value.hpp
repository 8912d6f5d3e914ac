#pragma once
// Owns an object of a class derived from T and copies it deeply (T::clone()), so that specs of
// many kinds can live in copyable scenes.
#include <memory>
#include <string>
#include <typeinfo>

#include <jelly/core/errors.hpp>

namespace jelly {

// A copyable owner of a T of any derived class: copies clone the object (T::clone()).
template <typename T>
class PolymorphicValue {
 public:
  // Holds nothing.
  PolymorphicValue() = default;
  // Takes ownership of `p` (implicit, so that a std::unique_ptr<Derived> converts).
  PolymorphicValue(std::unique_ptr<T> p) : p_(std::move(p)) {}  // NOLINT: implicit on purpose
  // A copy of `value`, of its own class U.
  template <typename U>
  PolymorphicValue(const U& value) : p_(std::make_unique<U>(value)) {}  // NOLINT
  // A deep copy (clone()).
  PolymorphicValue(const PolymorphicValue& o) : p_(o.p_ ? o.p_->clone() : nullptr) {}
  // Takes the object of `o`, which then holds nothing.
  PolymorphicValue(PolymorphicValue&&) noexcept = default;
  // A deep copy (clone()).
  PolymorphicValue& operator=(const PolymorphicValue& o) {
    if (this != &o) p_ = o.p_ ? o.p_->clone() : nullptr;
    return *this;
  }
  // Takes the object of `o`, which then holds nothing.
  PolymorphicValue& operator=(PolymorphicValue&&) noexcept = default;

  // True when it holds an object.
  explicit operator bool() const { return p_ != nullptr; }
  // The object, or nullptr.
  T* get() { return p_.get(); }
  // The object, or nullptr.
  const T* get() const { return p_.get(); }
  // The object (it must hold one).
  T* operator->() { return p_.get(); }
  // The object (it must hold one).
  const T* operator->() const { return p_.get(); }
  // The object (it must hold one).
  T& operator*() { return *p_; }
  // The object (it must hold one).
  const T& operator*() const { return *p_; }

  // The object as its concrete class U; throws InputError when it is of another kind.
  template <typename U>
  U& as() {
    U* u = dynamic_cast<U*>(p_.get());
    if (u == nullptr) throw InputError("the spec is not a " + std::string(typeid(U).name()));
    return *u;
  }
  // The object as its concrete class U; throws InputError when it is of another kind.
  template <typename U>
  const U& as() const {
    return const_cast<PolymorphicValue*>(this)->as<U>();
  }
  // True when the object is a U (or derived from it).
  template <typename U>
  bool is() const {
    return dynamic_cast<const U*>(p_.get()) != nullptr;
  }

 private:
  std::unique_ptr<T> p_;
};

}  // namespace jelly
