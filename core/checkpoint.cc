#include "core/checkpoint.h"

#include "core/errors.h"
#include "core/atomic_file.h"

#include <boost/archive/archive_exception.hpp>
#include <boost/archive/binary_iarchive.hpp>
#include <boost/archive/binary_oarchive.hpp>
#include <boost/serialization/string.hpp>

#include <fstream>
#include <new>
#include <sstream>
#include <stdexcept>

namespace tribo
{
  namespace
  {
    /// First entry of every checkpoint: what it is and its layout version (2: the wall time
    /// follows the parameters, and the SPH and MLP scenes checkpoint; 3: the SPH solver
    /// carries its viscous heat; 4: a particle first body carries its chain's mean
    /// velocity over the last step, the shear scene its upper body's speed at Shear start;
    /// 5: the NSCD run's record carries the steps above the gap target and the fastest
    /// body's speed).
    const std::string magic = "tribo checkpoint 5";
  } // namespace

  void write_checkpoint(const std::string &path, const std::function<void(CheckpointOut &)> &save)
  {
    std::ostringstream os(std::ios::binary);
    {
      CheckpointOut ar(os);
      ar << magic;
      save(ar);
      const std::string end = "end";
      ar << end;
    }
    atomic_write(path, os.str());
  }

  void read_checkpoint(const std::string &path, const std::function<void(CheckpointIn &)> &load,
                       bool whole)
  {
    std::ifstream in(path, std::ios::binary);
    if (!in)
      throw InputError("checkpoint " + path + ": cannot be read (no checkpoint was written there?)");
    try
      {
        CheckpointIn ar(in);
        std::string  head;
        ar >> head;
        if (head != magic)
          throw InputError("checkpoint " + path + ": not a checkpoint of this version of tribo");
        load(ar);
        if (!whole)
          return;
        std::string end;
        ar >> end;
        if (end != "end")
          throw InputError("checkpoint " + path + ": its content does not match this case "
                           "(the state ends in the wrong place)");
      }
    catch (const boost::archive::archive_exception &e)
      {
        throw InputError("checkpoint " + path + ": unreadable (" + std::string(e.what()) +
                         "); it was written by another build or for another case");
      }
    catch (const std::length_error &)
      {
        // A count read from the wrong place (another build's layout) sized a container.
        throw InputError("checkpoint " + path + ": unreadable (a size out of range); it was "
                         "written by another build or for another case");
      }
    catch (const std::bad_alloc &)
      {
        throw InputError("checkpoint " + path + ": unreadable (a size too large to allocate); it was "
                         "written by another build or for another case");
      }
  }
} // namespace tribo
