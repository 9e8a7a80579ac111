#include "dem/parallel/grain_ownership.h"

#include "dem/parallel/all_gather.h"

#include <boost/serialization/vector.hpp>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <map>

namespace tribo::dem::parallel
{
  namespace
  {
    /// Doubles per grain's state in a message: serial body number, x, y, angle, vx, vy, spin.
    constexpr std::size_t state_width = 7;
  } // namespace

  std::vector<bool> grains_of(const ParticleSystem &system)
  {
    std::vector<unsigned int> discs(system.bodies.size(), 0);
    for (const Disc &d : system.discs)
      ++discs[d.body];
    std::vector<bool> grain(system.bodies.size());
    for (std::size_t b = 0; b < grain.size(); ++b)
      grain[b] = discs[b] == 1;
    return grain;
  }

  GrainOwnership::GrainOwnership(MPI_Comm comm, double margin)
    : comm(comm)
    , rank(dealii::Utilities::MPI::this_mpi_process(comm))
    , ranks(dealii::Utilities::MPI::n_mpi_processes(comm))
    , margin(margin)
  {}

  void GrainOwnership::start(const ParticleSystem &system, const BandPartition &partition)
  {
    bands = partition;
    grain = grains_of(system);
    const std::size_t n = system.bodies.size();
    held_flag.assign(n, 0);
    owner_of.assign(n, 0);
    global.assign(n, 0);
    for (std::size_t b = 0; b < n; ++b)
      {
        if (!grain[b])
          {
            held_flag[b] = 1;
            continue;
          }
        const double y = system.bodies[b].position.y();
        owner_of[b]    = bands.band_of(y);
        held_flag[b]   = in_widened_band(y);
      }
    number(system);
  }

  const std::vector<unsigned int> &GrainOwnership::send_states(ParticleSystem &system)
  {
    // To the ranks that hold each owned grain (holders, by body) and to those whose widened
    // band holds its new centre.
    std::map<unsigned int, std::vector<double>> out;
    auto                                        held_by = holders.begin();
    for (const unsigned int b : owned_grains)
      {
        const RigidBody &body  = system.bodies[b];
        const auto       state = {double(b), body.position.x(), body.position.y(), body.angle,
                                  body.velocity.x(),     body.velocity.y(),   body.spin};
        const auto [first, last] = widened_bands(body.position.y());
        for (unsigned int s = first; s <= last; ++s)
          if (s != rank)
            out[s].insert(out[s].end(), state);
        for (; held_by != holders.end() && held_by->first == b; ++held_by)
          if (held_by->second < first || held_by->second > last)
            out[held_by->second].insert(out[held_by->second].end(), state);
      }
    received.clear();
    for (const auto &[from, states] : dealii::Utilities::MPI::some_to_some(comm, out))
      for (std::size_t i = 0; i + state_width <= states.size(); i += state_width)
        {
          const auto b    = static_cast<unsigned int>(states[i]);
          RigidBody &body = system.bodies[b];
          body.position   = {states[i + 1], states[i + 2]};
          body.angle      = states[i + 3];
          body.velocity   = {states[i + 4], states[i + 5]};
          body.spin       = states[i + 6];
          received.push_back(b);
        }
    return received;
  }

  void GrainOwnership::settle(const ParticleSystem &system)
  {
    // The grains held or received are current here: each owned by the band of its centre,
    // held when that is this band or its centre lies in the widened band.
    const auto place = [&](unsigned int b) {
      const double y = system.bodies[b].position.y();
      owner_of[b]    = bands.band_of(y);
      held_flag[b]   = in_widened_band(y);
    };
    for (const unsigned int b : held_bodies)
      if (grain[b])
        place(b);
    for (const unsigned int b : received)
      place(b);
    received.clear();
    number(system);
  }

  void GrainOwnership::number(const ParticleSystem &system)
  {
    held_bodies.clear();
    owned_grains.clear();
    for (unsigned int b = 0; b < held_flag.size(); ++b)
      if (held_flag[b])
        {
          held_bodies.push_back(b);
          if (grain[b] && owner_of[b] == rank)
            owned_grains.push_back(b);
        }
    const std::vector<std::uint64_t> counts = dealii::Utilities::MPI::all_gather(comm, std::uint64_t(owned_grains.size()));
    std::uint64_t first = 0;
    total               = 0;
    for (unsigned int s = 0; s < ranks; ++s)
      {
        if (s < rank)
          first += counts[s];
        total += counts[s];
      }
    std::map<unsigned int, std::vector<double>> out;
    holders.clear();
    for (const unsigned int b : owned_grains)
      {
        global[b]                  = first++;
        const auto [lowest, highest] = widened_bands(system.bodies[b].position.y());
        for (unsigned int s = lowest; s <= highest; ++s)
          if (s != rank)
            {
              out[s].insert(out[s].end(), {double(b), double(global[b])});
              holders.emplace_back(b, s);
            }
      }
    for (const auto &[from, numbers] : dealii::Utilities::MPI::some_to_some(comm, out))
      for (std::size_t i = 0; i + 2 <= numbers.size(); i += 2)
        global[static_cast<unsigned int>(numbers[i])] = static_cast<std::uint64_t>(numbers[i + 1]);
  }

  void GrainOwnership::sum_on_owners(std::vector<Eigen::Vector3d> &per_body) const
  {
    std::map<unsigned int, std::vector<double>> out;
    std::vector<double>                         replicated;
    for (const unsigned int b : held_bodies)
      if (!grain[b])
        replicated.insert(replicated.end(), per_body[b].data(), per_body[b].data() + 3);
      else if (owner_of[b] != rank)
        {
          if (!per_body[b].isZero())
            out[owner_of[b]].insert(out[owner_of[b]].end(), {double(b), per_body[b].x(), per_body[b].y(), per_body[b].z()});
          per_body[b].setZero();
        }
    for (const auto &[from, entries] : dealii::Utilities::MPI::some_to_some(comm, out))
      for (std::size_t i = 0; i + 4 <= entries.size(); i += 4)
        per_body[static_cast<unsigned int>(entries[i])] += Eigen::Vector3d(entries[i + 1], entries[i + 2], entries[i + 3]);
    sum_with_the_same_bits(replicated.data(), replicated.size(), comm);
    std::size_t k = 0;
    for (const unsigned int b : held_bodies)
      if (!grain[b])
        per_body[b] = Eigen::Vector3d(replicated[k], replicated[k + 1], replicated[k + 2]), k += 3;
  }

  void GrainOwnership::gather(ParticleSystem &system) const
  {
    struct Record
    {
      std::uint64_t body;
      double        state[6];
    };
    std::vector<Record> mine;
    mine.reserve(owned_grains.size());
    for (const unsigned int b : owned_grains)
      {
        const RigidBody &body = system.bodies[b];
        mine.push_back({b, {body.position.x(), body.position.y(), body.angle, body.velocity.x(),
                                       body.velocity.y(), body.spin}});
      }
    for (const Record &r : all_gathered(mine, comm))
      {
        RigidBody &body = system.bodies[r.body];
        body.position      = {r.state[0], r.state[1]};
        body.angle         = r.state[2];
        body.velocity      = {r.state[3], r.state[4]};
        body.spin          = r.state[5];
      }
  }
} // namespace tribo::dem::parallel
