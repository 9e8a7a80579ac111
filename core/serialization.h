#pragma once
/// @file What a checkpoint's save() and load() functions need (core/checkpoint.h): the two
/// archive types and the Boost.Serialization of the value types the modules hold, so that
/// `ar << v` and `ar >> v` work for std::vector, std::array, std::map, std::pair and
/// std::string of doubles, integers, deal.II Tensor and SymmetricTensor (their own
/// serialize()) and fixed-size Eigen vectors and matrices (below). Doubles are stored bit
/// for bit.

#include "core/checkpoint.h"

#include <Eigen/Core>

#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/array.hpp>
#include <boost/serialization/map.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>

#include <sstream>
#include <string>

namespace boost::serialization
{
  /// A fixed-size Eigen matrix (dem::Vec2, mlp::Vec2, ...), coefficient by coefficient,
  /// in either direction.
  template <class Archive, typename Scalar, int Rows, int Cols, int Options, int MaxRows, int MaxCols>
  void serialize(Archive &ar, Eigen::Matrix<Scalar, Rows, Cols, Options, MaxRows, MaxCols> &m,
                 const unsigned int /*version*/)
  {
    static_assert(Rows > 0 && Cols > 0, "only fixed-size Eigen matrices are checkpointed");
    for (Eigen::Index i = 0; i < m.size(); ++i)
      ar &m.data()[i];
  }
} // namespace boost::serialization

namespace tribo
{
  /// The state of a standard random-number engine (e.g. std::mt19937_64) as text, for a
  /// checkpoint: set_engine_state() of it continues the same sequence.
  template <class Engine>
  std::string engine_state(const Engine &engine)
  {
    std::ostringstream os;
    os << engine;
    return os.str();
  }

  /// Restore an engine from engine_state().
  template <class Engine>
  void set_engine_state(Engine &engine, const std::string &state)
  {
    std::istringstream is(state);
    is >> engine;
  }
} // namespace tribo
