#include "dem/parallel/rank_problem.h"

#include <algorithm>
#include <numeric>
#include <utility>

namespace tribo::dem::parallel
{
  double disc_height(const ParticleSystem &system, unsigned int d)
  {
    const Disc &disc = system.discs[d];
    return disc.offset.x() == 0 && disc.offset.y() == 0 ? system.bodies[disc.body].position.y() : system.disc_centre(d).y();
  }

  namespace
  {

    /// Height of the midpoint of contact @p c's two disc centres, m; a half-disc contact's,
    /// its grain's.
    double contact_height(const ParticleSystem &system, const Contact &c)
    {
      if (c.on_boundary())
        return disc_height(system, c.disc[1]);
      return 0.5 * (disc_height(system, c.disc[0]) + disc_height(system, c.disc[1]));
    }
  } // namespace

  std::vector<double> disc_heights(const ParticleSystem &system)
  {
    std::vector<double> y(system.discs.size());
    for (std::size_t d = 0; d < y.size(); ++d)
      y[d] = disc_height(system, static_cast<unsigned int>(d));
    return y;
  }

  std::vector<double> contact_heights(const ParticleSystem &system, const std::vector<Contact> &contacts)
  {
    std::vector<double> y(contacts.size());
    for (std::size_t i = 0; i < contacts.size(); ++i)
      y[i] = contact_height(system, contacts[i]);
    return y;
  }

  BandPartition contact_bands(const ParticleSystem &system, const std::vector<Contact> &contacts, unsigned int n)
  {
    return BandPartition::balanced(contact_heights(system, contacts), n);
  }

  RankProblem share_of(const ParticleSystem &system, const std::vector<Contact> &contacts, const BodyState &state,
                       const BandPartition &bands, unsigned int rank)
  {
    return share_of(system, contacts, contact_heights(system, contacts), state, bands, rank);
  }

  namespace
  {
    /// @p p's bodies for its owned contacts, @p contacts[p.serial_contact[k]] (p.contacts
    /// not filled): the grains' global numbers, the local bodies and their state.
    void number_bodies(RankProblem &p, const ParticleSystem &system, const std::vector<Contact> &contacts,
                       const BodyState &state, const BandPartition &bands, unsigned int rank,
                       const GrainOwnership *ownership)
    {
      const std::size_t n_bodies = system.bodies.size();
      std::vector<unsigned int> owned, ghosts, replicated;
      std::vector<std::uint64_t> global_of; // without an ownership: every body's global number
      const auto global = [&](unsigned int b) { return ownership ? ownership->global_number(b) : global_of[b]; };
      if (ownership)
        {
          // The ownership's grains and numbers (this rank's copies of the others are stale):
          // its owned grains, the grains the owned contacts touch beyond them, the walls.
          p.n_grains = ownership->n_grains();
          owned      = ownership->owned();
          for (const unsigned int b : ownership->held())
            if (!ownership->is_grain(b))
              replicated.push_back(b);
          std::vector<char> seen(n_bodies, 0);
          for (const unsigned int i : p.serial_contact)
            for (int s = contacts[i].on_boundary() ? 1 : 0; s < 2; ++s)
              if (const unsigned int b = contacts[i].body[s];
                  ownership->is_grain(b) && !ownership->owns(b) && !std::exchange(seen[b], 1))
                ghosts.push_back(b);
        }
      else
        {
          // Global numbers: the grains band by band, each band's in serial order.
          const std::vector<bool>    grain = grains_of(system);
          std::vector<unsigned int>  band(n_bodies, 0);
          std::vector<std::uint64_t> count(bands.n_bands() + 1, 0);
          for (std::size_t b = 0; b < n_bodies; ++b)
            if (grain[b])
              ++count[(band[b] = bands.band_of(system.bodies[b].position.y())) + 1];
          for (unsigned int k = 0; k < bands.n_bands(); ++k)
            count[k + 1] += count[k]; // count[k]: the first global number of band k
          p.n_grains = count[bands.n_bands()];
          global_of.assign(n_bodies, 0);
          for (std::size_t b = 0; b < n_bodies; ++b)
            if (grain[b])
              global_of[b] = count[band[b]]++;
          // The grains the owned contacts touch.
          std::vector<bool> touched(n_bodies, false);
          for (const unsigned int i : p.serial_contact)
            for (int s = contacts[i].on_boundary() ? 1 : 0; s < 2; ++s)
              touched[contacts[i].body[s]] = true;
          for (unsigned int b = 0; b < n_bodies; ++b)
            if (!grain[b])
              replicated.push_back(b);
            else if (band[b] == rank)
              owned.push_back(b);
            else if (touched[b])
              ghosts.push_back(b);
        }
      const auto by_global = [&](unsigned int a, unsigned int b) { return global(a) < global(b); };
      for (auto *list : {&owned, &ghosts}) // an ownership's owned grains come sorted
        if (!std::is_sorted(list->begin(), list->end(), by_global))
          std::sort(list->begin(), list->end(), by_global);
      p.n_owned = static_cast<unsigned int>(owned.size());
      p.n_ghost = static_cast<unsigned int>(ghosts.size());
      for (const auto *list : {&owned, &ghosts, &replicated})
        p.serial_body.insert(p.serial_body.end(), list->begin(), list->end());

      p.local_body.assign(n_bodies, 0);
      p.state.velocity.reserve(p.serial_body.size());
      p.state.inverse_mass.reserve(p.serial_body.size());
      p.global_grain.reserve(p.n_owned + p.n_ghost);
      for (unsigned int l = 0; l < p.serial_body.size(); ++l)
        {
          const unsigned int b = p.serial_body[l];
          p.local_body[b]      = l;
          p.state.velocity.push_back(state.velocity[b]);
          p.state.inverse_mass.push_back(state.inverse_mass[b]);
          if (l < p.n_owned + p.n_ghost)
            p.global_grain.push_back(global(b));
        }
      if (rank == bands.n_bands() - 1)
        {
          p.state.node_velocity = state.node_velocity;
          p.state.node_blocks   = state.node_blocks;
        }
    }

    /// @p c's bodies in @p p's local numbers.
    void to_local(const RankProblem &p, Contact &c)
    {
      c.body[1] = p.local_body[c.body[1]];
      // A half-disc contact's unused side 0 names its grain too: a local body, and no
      // other rank's.
      c.body[0] = c.on_boundary() ? c.body[1] : p.local_body[c.body[0]];
    }
  } // namespace

  RankProblem share_of(const ParticleSystem &system, const std::vector<Contact> &contacts,
                       const std::vector<double> &heights, const BodyState &state, const BandPartition &bands,
                       unsigned int rank)
  {
    // Owned contacts. A half-disc contact belongs to the top band, whatever its height: a
    // boundary body's contacts are coupled by its compliance, so one rank holds them all,
    // and its nodes' velocities (side 0; body[0] unused).
    RankProblem        p;
    const unsigned int top = bands.n_bands() - 1;
    for (std::size_t i = 0; i < contacts.size(); ++i)
      if ((contacts[i].on_boundary() ? top : bands.band_of(heights[i])) == rank)
        p.serial_contact.push_back(static_cast<unsigned int>(i));
    number_bodies(p, system, contacts, state, bands, rank, nullptr);
    p.contacts.resize(p.serial_contact.size());
    for (std::size_t k = 0; k < p.contacts.size(); ++k)
      to_local(p, p.contacts[k] = contacts[p.serial_contact[k]]);
    return p;
  }

  RankProblem own_share(const ParticleSystem &system, std::vector<Contact> &contacts, const BodyState &state,
                        const BandPartition &bands, unsigned int rank, const GrainOwnership *ownership)
  {
    RankProblem p;
    p.serial_contact.resize(contacts.size());
    std::iota(p.serial_contact.begin(), p.serial_contact.end(), 0u);
    number_bodies(p, system, contacts, state, bands, rank, ownership);
    p.contacts.swap(contacts);
    for (Contact &c : p.contacts)
      to_local(p, c);
    return p;
  }

  void give_back(RankProblem &p, std::vector<Contact> &contacts)
  {
    for (Contact &c : p.contacts)
      {
        c.body[1] = p.serial_body[c.body[1]];
        c.body[0] = p.serial_body[c.body[0]];
      }
    contacts.swap(p.contacts);
  }
} // namespace tribo::dem::parallel
