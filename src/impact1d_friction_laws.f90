!> The friction laws beyond Coulomb against a still ground (docs/method.md section 12): a
!> moving friction surface (a belt under each body, its speed V(t) = belt_v + belt_amp
!> sin(2 pi t / belt_period + belt_phase), the sine only where named) and Stribeck's
!> velocity-dependent sliding friction (`v_s`, `c_v`). Friction acts on the slip, the
!> velocity relative to the surface, u = v - V(t); a body sticks when u = 0 (it moves
!> with the belt, accelerating at V'(t)), and slides with the bound
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
  public :: belt_speed, belt_rate, belt_moving, belt_displacement, shift_to_belts, belt_accelerations

contains

  !> Body i's slip at time t: its velocity v relative to its friction surface.
  pure real(wp) function slip(scene, i, v, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: v, t
    slip = v
    if (scene%belts) slip = v - belt_speed(scene, i, t)
  end function slip

  !> The speed V_i(t) of body i's belt (a scene with belts): belt_v, plus its sine where
  !> belt_amp names one (impact1d_scene's add_belt_sine, through a pointer: see there; a
  !> constant belt reads body_belt alone, the same bits as before).
  pure real(wp) function belt_speed(scene, i, t) result(speed)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: t
    speed = scene%body_belt(i)
    if (scene%belt_moves) speed = scene%belt_sine(scene, i, t, speed)
  end function belt_speed

  !> Whether body i's belt has a sine speed (its stuck body accelerates).
  pure logical function belt_moving(scene, i)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    belt_moving = .false.
    if (scene%belt_moves) belt_moving = scene%body_belt_amp(i) /= 0.0_wp
  end function belt_moving

  !> V_i'(t) (order 2: the belt's acceleration, as a moving ground's w'') or V_i''(t) (3);
  !> 0 on a belt of constant speed.
  pure real(wp) function belt_rate(scene, i, t, order) result(rate)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i, order
    real(wp), intent(in) :: t
    rate = 0.0_wp
    if (.not. belt_moving(scene, i)) return
    associate (amp => scene%body_belt_amp(i), omega => scene%body_belt_omega(i), &
        phase => scene%body_belt_phase(i))
      if (order == 2) then
        rate = amp * omega * cos(omega * t + phase)
      else
        rate = -amp * omega**2 * sin(omega * t + phase)
      end if
    end associate
  end function belt_rate

  !> How far body i's belt moves from t to t + h, the integral of V_i: belt_v h + (amp /
  !> omega) (cos(a) - cos(a + omega h)), formed as 2 (amp / omega) sin(a + omega h / 2)
  !> sin(omega h / 2), accurate however small h is against t (impact1d_drives'
  !> displacement).
  pure real(wp) function belt_displacement(scene, i, t, h) result(dx)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: t, h
    dx = scene%body_belt(i) * h
    if (.not. belt_moving(scene, i)) return
    associate (amp => scene%body_belt_amp(i), omega => scene%body_belt_omega(i), &
        phase => scene%body_belt_phase(i))
      dx = dx + 2.0_wp * (amp / omega) * sin(omega * (t + 0.5_wp * h) + phase) * sin(0.5_wp * omega * h)
    end associate
  end function belt_displacement

  !> f and its rate df as seen from each accelerating belt under a body at rest on it
  !> (slip 0 at t, velocities v): f - m V'(t), df - m V''(t). Solved so, a body at rest on
  !> an accelerating belt is the body at rest on a still one: it sticks while the force the
  !> stick needs, m V' - f, stays within S (impact1d_body_mode's shift_to_drives for a body
  !> held to a moving ground). Bodies with contacts have no such belt (refused).
  pure subroutine shift_to_belts(scene, t, v, f, df)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v(:)
    real(wp), intent(inout) :: f(:), df(:)
    integer :: i
    do i = 1, scene%n_bodies
      if (.not. belt_moving(scene, i)) cycle
      if (slip(scene, i, v(i), t) /= 0.0_wp) cycle
      f(i) = f(i) - scene%body_mass(i) * belt_rate(scene, i, t, 2)
      df(i) = df(i) - scene%body_mass(i) * belt_rate(scene, i, t, 3)
    end do
  end subroutine shift_to_belts

  !> a(i) := V_i'(t) (order 2) or V_i''(t) (3) of each stuck body on an accelerating belt
  !> (after the mode's accelerations, whose group 0 is still: impact1d_body_mode's
  !> drive_accelerations for a moving ground).
  pure subroutine belt_accelerations(scene, stuck, t, order, a)
    type(scene_type), intent(in) :: scene
    logical, intent(in) :: stuck(:)
    real(wp), intent(in) :: t
    integer, intent(in) :: order
    real(wp), intent(inout) :: a(:)
    integer :: i
    do i = 1, scene%n_bodies
      if (stuck(i) .and. belt_moving(scene, i)) a(i) = belt_rate(scene, i, t, order)
    end do
  end subroutine belt_accelerations

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
  !> f_slide) on each body that slides (sgn /= 0) at velocities v, time t: -(c(u) - F) sgn.
  !> A force of the state, which RK4's stages carry.
  pure subroutine add_stribeck_forces(scene, sgn, v, t, f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: sgn(:), v(:), t
    real(wp), intent(inout) :: f(:)
    integer :: i
    do i = 1, scene%n_bodies
      if (sgn(i) == 0.0_wp) cycle
      f(i) = f(i) - (sliding_bound(scene, i, slip(scene, i, v(i), t)) - scene%body_friction(i)) * sgn(i)
    end do
  end subroutine add_stribeck_forces

  !> At one instant t of a step: the power friction dissipates (loss: -f_fr u summed over
  !> the sliding bodies) and the power the belts put in (belt: f_fr V(t) over the sliding
  !> bodies, and over the bodies held in the mode's frame (group 0, no moving ground) the
  !> force that holds them, -(f + f_slide), at their velocity, which is their belt's; on a
  !> belt of sine speed the holding force has m V'(t) beside it, whose work, the body's
  !> kinetic energy, impact1d_nbody_step's hold_to_belts books exactly). f: the applied
  !> forces with add_stribeck_forces' part; f_slide, sgn, group, drive: the mode's; v: the
  !> velocities.
  pure subroutine law_powers(scene, f_slide, sgn, group, drive, f, v, t, loss, belt)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: f_slide(:), sgn(:), f(:), v(:), t
    integer, intent(in) :: group(:), drive(:)
    real(wp), intent(out) :: loss, belt
    real(wp) :: friction, speed, u
    integer :: i
    loss = 0.0_wp
    belt = 0.0_wp
    do i = 1, scene%n_bodies
      if (sgn(i) /= 0.0_wp) then
        ! (slip's u = v - V(t) with V formed once: three belt_speed's, each testing for a
        ! sine, cost a constant belt's stage 1%, callgrind)
        speed = 0.0_wp
        u = v(i)
        if (scene%belts) then
          speed = belt_speed(scene, i, t)
          u = v(i) - speed
        end if
        friction = -sliding_bound(scene, i, u) * sgn(i)
        loss = loss - friction * u
        if (scene%belts) belt = belt + friction * speed
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
