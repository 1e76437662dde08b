!> The rounding yardsticks of the solver, in one place: what counts as zero for a gap, a
!> velocity, an instant and a force, each a multiple of the unit roundoff of the quantity
!> it guards.
module impact1d_yardsticks
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_scene, only: scene_type
  implicit none
  private
  public :: gap_rounding, velocity_rounding, time_rounding, energy_rounding, force_scale, same_instant

  !> Rounding of a gap, per unit it moved: a gap is exact to its own size (compensated
  !> positions, exact differences), so only what a step moved it by and the low parts count.
  real(wp), parameter :: gap_rounding = 16.0_wp * eps_wp
  !> A velocity this small against the speeds it came from is zero.
  real(wp), parameter :: velocity_rounding = 64.0_wp * eps_wp
  !> Instants closer than this (relative to the clock) coincide.
  real(wp), parameter :: time_rounding = 64.0_wp * eps_wp
  !> Relative rounding of a kinetic energy after an impulse (a sum of positive terms, each
  !> velocity a few roundings off): an elastic impact may end this much above where it began.
  real(wp), parameter :: energy_rounding = 1024.0_wp * eps_wp

contains

  !> Size of the forces around an instant, for rounding tolerances: a force crossing zero
  !> is still as large as what a step changes it by.
  pure real(wp) function force_scale(scene, f, df)
    type(scene_type), intent(in) :: scene
    real(wp), contiguous, intent(in) :: f(:), df(:)
    force_scale = sum(abs(f)) + 2.0_wp * sum(scene%body_static) + sum(abs(df)) * scene%dt
  end function force_scale

  !> Instants closer than the clock resolves are one (t_later >= t_earlier).
  pure logical function same_instant(scene, t_later, t_earlier)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t_later, t_earlier
    same_instant = t_later - t_earlier <= time_rounding * max(abs(t_later), scene%dt)
  end function same_instant
end module impact1d_yardsticks
