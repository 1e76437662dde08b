!> The friction laws beyond Coulomb against a still ground (docs/method.md section 12): a
!> moving friction surface (a belt under each body, `belt_v`, constant) and Stribeck's
!> velocity-dependent sliding friction (`v_s`, `c_v`). Friction acts on the slip, the
!> velocity relative to the surface, u = v - belt_v; a body sticks when u = 0 (it moves
!> with the belt), and slides with the bound
!>   c(u) = F + (S - F) exp(-(u / v_s)^2) + C |u|,
!> F = mu m g, S = mus m g, C = c_v m g (Coulomb: c = F). Only the N-body engine runs these
!> laws (impact1d_solver's run hands it every scene that names one); a scene that names none
!> never enters this module's work (scene_type's belts and stribeck false).
module impact1d_friction_laws
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  implicit none
  private
  public :: slip, sliding_bound, add_stribeck_forces, law_powers, contact_loss

contains

  !> Body i's slip: its velocity v relative to its friction surface.
  pure real(wp) function slip(scene, i, v)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: v
    slip = v
    if (scene%belts) slip = v - scene%body_belt(i)
  end function slip

  !> Body i's sliding friction bound c(u) at slip u (the module header); at u = 0 it is the
  !> bound a body breaking away slides with: S under Stribeck's law (mu(0) = mus), F under
  !> Coulomb's (v_s not named).
  pure real(wp) function sliding_bound(scene, i, u) result(c)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: u
    c = scene%body_friction(i)
    if (.not. scene%stribeck) return
    if (scene%body_v_s(i) > 0.0_wp) c = c + (scene%body_static(i) - scene%body_friction(i)) * &
      exp(-(u / scene%body_v_s(i))**2)
    c = c + scene%body_viscous(i) * abs(u)
  end function sliding_bound

  !> f := f plus the part of sliding friction beyond the mode's constant -F sgn (the mode's
  !> f_slide) on each body that slides (sgn /= 0) at velocities v: -(c(u) - F) sgn. A force
  !> of the state, which RK4's stages carry.
  pure subroutine add_stribeck_forces(scene, sgn, v, f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: sgn(:), v(:)
    real(wp), intent(inout) :: f(:)
    integer :: i
    do i = 1, scene%n_bodies
      if (sgn(i) == 0.0_wp) cycle
      f(i) = f(i) - (sliding_bound(scene, i, slip(scene, i, v(i))) - scene%body_friction(i)) * sgn(i)
    end do
  end subroutine add_stribeck_forces

  !> At one instant of a step: the power friction dissipates (loss: -f_fr u summed over the
  !> sliding bodies) and the power the belts put in (belt: f_fr belt_v over the sliding
  !> bodies, and over the bodies held still in the mode's frame (group 0, no moving ground)
  !> the force that holds them, -(f + f_slide), at their velocity, which is their belt's).
  !> f: the applied forces with add_stribeck_forces' part; f_slide, sgn, group, drive: the
  !> mode's; v: the velocities.
  pure subroutine law_powers(scene, f_slide, sgn, group, drive, f, v, loss, belt)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: f_slide(:), sgn(:), f(:), v(:)
    integer, intent(in) :: group(:), drive(:)
    real(wp), intent(out) :: loss, belt
    real(wp) :: friction
    integer :: i
    loss = 0.0_wp
    belt = 0.0_wp
    do i = 1, scene%n_bodies
      if (sgn(i) /= 0.0_wp) then
        friction = -sliding_bound(scene, i, slip(scene, i, v(i))) * sgn(i)
        loss = loss - friction * slip(scene, i, v(i))
        if (scene%belts) belt = belt + friction * scene%body_belt(i)
      end if
      if (scene%belts .and. group(i) == 0 .and. drive(i) == 0) belt = belt - (f(i) + f_slide(i)) * v(i)
    end do
  end subroutine law_powers

  !> The power the friction contacts between bodies (&friction) dissipate at velocities v:
  !> F |u| over those that slide (friction_sgn, the mode's), u = v_b - v_a. law_powers books
  !> the bodies' own friction only; a contact's force, in f_slide, does no work on a belt
  !> (its law stays Coulomb's, on the relative velocity: the belts are under the bodies).
  pure real(wp) function contact_loss(scene, friction_sgn, v) result(loss)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: friction_sgn(:), v(:)
    integer :: j
    loss = 0.0_wp
    do j = 1, scene%n_frictions
      if (friction_sgn(j) == 0.0_wp) cycle
      loss = loss + scene%friction_slide(j) * friction_sgn(j) * (v(scene%friction_body(2, j)) - &
        v(scene%friction_body(1, j)))
    end do
  end function contact_loss
end module impact1d_friction_laws
