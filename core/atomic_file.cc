#include "core/atomic_file.h"

#include "core/errors.h"

#include <cstdio>
#include <fstream>

namespace tribo
{
  void atomic_write(const std::string &path, const std::string &content)
  {
    const std::string tmp = path + ".tmp";
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out)
        throw RunError("cannot write " + tmp);
      out << content;
      out.flush();
      if (!out)
        throw RunError("failed writing " + tmp + " (disk full?)");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0)
      throw RunError("cannot rename " + tmp + " to " + path);
  }
} // namespace tribo
