#include "millsim/sim/world.hpp"

#include <algorithm>

namespace millsim {
namespace {

ContactType wall_contact_type(WallKind kind) {
  switch (kind) {
    case WallKind::shell:
      return ContactType::ball_shell;
    case WallKind::lifter:
      return ContactType::ball_lifter;
    case WallKind::plane:
      return ContactType::ball_plane;
  }
  return ContactType::ball_plane;
}

}  // namespace

template <int D>
World<D>::World(const WorldSettings<D>& settings, const Walls<D>& walls)
    : settings_(settings),
      walls_(walls),
      ball_ball_law_(settings.ball_ball, settings.allow_tension),
      ball_wall_law_(settings.ball_wall, settings.allow_tension),
      neighbours_(settings.skin) {
  if (walls_.mill) walls_.mill->turn_to(walls_.mill->angle);
}

template <int D>
void World<D>::step() {
  refresh_neighbours();
  estimate_current_velocities();
  evaluate_pair_contacts();
  evaluate_wall_contacts();
  accumulate_forces();
  integrate();
  advance_walls();
  time_ += settings_.time_step;
  ++steps_;
}

template <int D>
void World<D>::refresh_neighbours() {
  const std::size_t count = particles_.size();
  if (wall_slot_id_.size() != count * max_wall_contacts) {
    wall_slot_id_.assign(count * max_wall_contacts, -1);
    wall_slot_history_.assign(count * max_wall_contacts, ContactHistory<D>{});
  }
  if (!neighbours_.needs_refresh(particles_.position)) return;
  if (settings_.skin <= 0.0 && count > 0) {
    const double smallest = *std::min_element(particles_.radius.begin(), particles_.radius.end());
    settings_.skin = smallest;
    neighbours_ = NeighbourList<D>(settings_.skin);
  }
  neighbours_.rebuild(particles_.position, particles_.radius);
  pair_force_.resize(neighbours_.pair_count());
  pair_moment_.resize(neighbours_.pair_count());
}

template <int D>
void World<D>::estimate_current_velocities() {
  const std::size_t count = particles_.size();
  velocity_now_.resize(count);
  spin_now_.resize(count);
  const double half_step = 0.5 * settings_.time_step;
  for (std::size_t i = 0; i < count; ++i) {
    velocity_now_[i] =
        particles_.velocity[i] + (half_step * particles_.inverse_mass[i]) * particles_.force[i];
    spin_now_[i] = particles_.angular_velocity[i] +
                   (half_step * particles_.inverse_inertia[i]) * particles_.torque[i];
  }
}

template <int D>
void World<D>::end_collision(ContactType type, ContactHistory<D>& history) {
  if (spectrum_ != nullptr) spectrum_->record(type, history.dissipated);
  history = ContactHistory<D>{};
}

template <int D>
void World<D>::evaluate_pair_contacts() {
  const auto& first = neighbours_.first();
  const auto& second = neighbours_.second();
  auto& history = neighbours_.history();
  const auto& x = particles_.position;
  const auto& v = velocity_now_;
  const auto& w = spin_now_;
  const auto& step_v = particles_.velocity;
  const auto& step_w = particles_.angular_velocity;
  const auto& r = particles_.radius;
  const auto& m = particles_.mass;
  const double dt = settings_.time_step;
  double dissipated = 0.0;
  for (std::size_t p = 0; p < first.size(); ++p) {
    const std::uint32_t a = first[p];
    const std::uint32_t b = second[p];
    const Vec<D> offset = x[b] - x[a];
    const double distance_squared = norm_squared(offset);
    const double reach = r[a] + r[b];
    if (distance_squared >= reach * reach) {
      if (history[p].touching) end_collision(ContactType::ball_ball, history[p]);
      pair_force_[p] = Vec<D>{};
      pair_moment_[p] = Spin<D>{};
      continue;
    }
    const double distance = std::sqrt(distance_squared);
    ContactInput<D> in;
    in.normal = offset * (1.0 / distance);
    in.overlap = reach - distance;
    in.velocity = v[b] - v[a];
    in.spin_velocity = cross(in.normal, r[a] * w[a] + r[b] * w[b]);
    in.step_velocity = step_v[b] - step_v[a];
    in.step_spin_velocity = cross(in.normal, r[a] * step_w[a] + r[b] * step_w[b]);
    in.effective_mass = m[a] * m[b] / (m[a] + m[b]);
    history[p].touching = true;
    history[p].overlap = in.overlap;
    const ContactOutput<D> out = ball_ball_law_.evaluate(in, history[p], dt);
    pair_force_[p] = out.force;
    pair_moment_[p] = -cross(in.normal, out.tangential_force);
    dissipated += out.dissipated;
  }
  last_step_dissipation_ = dissipated;
}

template <int D>
void World<D>::evaluate_wall_contacts() {
  const double dt = settings_.time_step;
  double torque = 0.0;
  double work = 0.0;
  double dissipated = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    std::int32_t* slot_id = &wall_slot_id_[i * max_wall_contacts];
    ContactHistory<D>* slot_history = &wall_slot_history_[i * max_wall_contacts];
    std::array<bool, max_wall_contacts> seen{};
    Vec<D> force{};
    Spin<D> moment{};
    const double radius = particles_.radius[i];
    walls_.for_each_contact(particles_.position[i], radius, [&](const WallContact<D>& contact) {
      int slot = 0;
      while (slot < max_wall_contacts && slot_id[slot] != contact.wall_id) ++slot;
      if (slot == max_wall_contacts) {
        slot = 0;
        while (slot < max_wall_contacts && slot_id[slot] >= 0) ++slot;
        if (slot == max_wall_contacts) return;  // cannot happen: at most 4 walls reach a disc
        slot_id[slot] = contact.wall_id;
      }
      seen[static_cast<std::size_t>(slot)] = true;
      ContactInput<D> in;
      in.normal = contact.normal;
      in.overlap = contact.overlap;
      in.velocity = velocity_now_[i] - contact.wall_velocity;
      in.spin_velocity = cross(contact.normal, radius * spin_now_[i]);
      in.step_velocity = particles_.velocity[i] - contact.wall_velocity;
      in.step_spin_velocity = cross(contact.normal, radius * particles_.angular_velocity[i]);
      in.effective_mass = particles_.mass[i];
      ContactHistory<D>& history = slot_history[slot];
      history.touching = true;
      history.overlap = contact.overlap;
      const ContactOutput<D> out = ball_wall_law_.evaluate(in, history, dt);
      force += out.force;
      moment += -radius * cross(contact.normal, out.tangential_force);
      dissipated += out.dissipated;
      if (contact.kind != WallKind::plane) {
        if constexpr (D == 2) torque += cross(contact.point, out.force);
        work += dot(out.force, contact.wall_velocity) * dt;
      }
    });
    for (int slot = 0; slot < max_wall_contacts; ++slot) {
      if (slot_id[slot] < 0 || seen[static_cast<std::size_t>(slot)]) continue;
      const int id = slot_id[slot];
      const WallKind kind = walls_.mill && id == 0                           ? WallKind::shell
                            : walls_.mill && id <= walls_.mill->lifter_count ? WallKind::lifter
                                                                             : WallKind::plane;
      end_collision(wall_contact_type(kind), slot_history[slot]);
      slot_id[slot] = -1;
    }
    particles_.force[i] = force;
    particles_.torque[i] = moment;
  }
  shell_torque_ = torque;
  account_.shell_work += work;
  last_step_dissipation_ += dissipated;
  account_.dissipated += last_step_dissipation_;
}

template <int D>
void World<D>::accumulate_forces() {
  // Fixed order: pairs in list order, so the sums are the same on every run.
  const auto& first = neighbours_.first();
  const auto& second = neighbours_.second();
  auto& force = particles_.force;
  auto& torque = particles_.torque;
  const auto& r = particles_.radius;
  for (std::size_t p = 0; p < first.size(); ++p) {
    const std::uint32_t a = first[p];
    const std::uint32_t b = second[p];
    force[b] += pair_force_[p];
    force[a] -= pair_force_[p];
    torque[a] += r[a] * pair_moment_[p];
    torque[b] += r[b] * pair_moment_[p];
  }
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    force[i] += particles_.mass[i] * settings_.gravity;
  }
}

template <int D>
void World<D>::integrate() {
  // Leapfrog: u̇(n+½) = u̇(n−½) + ü(n) Δt, u(n+1) = u(n) + u̇(n+½) Δt; the same for rotation.
  const double dt = settings_.time_step;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    particles_.velocity[i] += (particles_.inverse_mass[i] * dt) * particles_.force[i];
    particles_.position[i] += dt * particles_.velocity[i];
    particles_.angular_velocity[i] += (particles_.inverse_inertia[i] * dt) * particles_.torque[i];
  }
}

template <int D>
void World<D>::advance_walls() {
  if (walls_.mill) {
    walls_.mill->turn_to(walls_.mill->angle + walls_.mill->angular_speed * settings_.time_step);
  }
}

template <int D>
std::size_t World<D>::touching_contacts() const {
  std::size_t count = 0;
  for (const auto& h : neighbours_.history()) count += h.touching ? 1 : 0;
  for (const auto id : wall_slot_id_) count += id >= 0 ? 1 : 0;
  return count;
}

template <int D>
double World<D>::kinetic_energy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    const double inertia = 1.0 / particles_.inverse_inertia[i];
    energy +=
        0.5 * particles_.mass[i] * norm_squared(particles_.velocity[i]) +
        0.5 * inertia * spin_dot(particles_.angular_velocity[i], particles_.angular_velocity[i]);
  }
  return energy;
}

template <int D>
double World<D>::potential_energy() const {
  double energy = 0.0;
  for (std::size_t i = 0; i < particles_.size(); ++i) {
    energy -= particles_.mass[i] * dot(settings_.gravity, particles_.position[i]);
  }
  return energy;
}

template <int D>
double World<D>::stored_spring_energy() const {
  double energy = 0.0;
  for (const auto& h : neighbours_.history()) {
    if (h.touching) energy += ball_ball_law_.stored_energy(h, h.overlap);
  }
  for (std::size_t s = 0; s < wall_slot_id_.size(); ++s) {
    if (wall_slot_id_[s] >= 0) {
      energy += ball_wall_law_.stored_energy(wall_slot_history_[s], wall_slot_history_[s].overlap);
    }
  }
  return energy;
}

template class World<2>;

}  // namespace millsim
