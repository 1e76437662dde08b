!> Stepping within a mode (METHOD.md 3): the classical RK4 step, its closed form under
!> constant forces, the exact ledger over such steps, and the step's dense output.
module impact1d_stepping
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_modes, only: mode_type
  use impact1d_events, only: hermite
  use impact1d_state, only: state_type, add_compensated, constant_step
  implicit none
  private
  public :: rk4_type, book_constant_ledger, books_ledger, dense_output

  !> What the integrator keeps between steps.
  type :: rk4_type
    !> No table, no sine: the forces are constant and so is each mode's acceleration.
    logical :: constant_forcing = .false.
    !> Tables and constants: the dense output is exact, so no root can be missed.
    logical :: polynomial_forcing = .false.
    !> The mode's acceleration under constant forces, worked out once at the event point.
    real(wp) :: constant_acceleration(2) = 0.0_wp
    !> The force at the end of the last step taken, and when: the next step's start force.
    real(wp) :: end_force(2) = 0.0_wp, end_force_t = -huge(1.0_wp)
    !> With springs the force depends on the state too: the state it was evaluated in.
    real(wp) :: end_x(2) = 0.0_wp, end_x_lo(2) = 0.0_wp, end_v(2) = 0.0_wp, end_v_lo(2) = 0.0_wp
    real(wp) :: end_external(2) = 0.0_wp   !< and its external (time-only) part
  contains
    procedure :: step => rk4_step
    procedure :: advance_constant
  end type rk4_type

contains

  !> One step of the mode under constant acceleration: RK4 is exact there, and its step is
  !> the quadratic x + h v + h^2 a / 2, v + h a.
  pure subroutine advance_constant(self, state, step)
    class(rk4_type), intent(in) :: self
    type(state_type), intent(inout) :: state
    real(wp), intent(in) :: step
    call add_compensated(state%t, state%t_lo, step)
    call constant_step(step, self%constant_acceleration, state%x, state%x_lo, state%v, state%v_lo)
  end subroutine advance_constant

  !> Under constant forces the work and the friction loss over any stretch of one mode are
  !> the forces times the displacement, exactly (no quadrature): from x_a to x_b, into s.
  pure subroutine book_constant_ledger(scene, mode, x_a, x_lo_a, x_b, x_lo_b, s)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    real(wp), intent(in) :: x_a(2), x_lo_a(2), x_b(2), x_lo_b(2)
    type(state_type), intent(inout) :: s
    real(wp) :: dx(2)
    if (.not. books_ledger(scene, mode)) return
    dx = (x_b - x_a) + (x_lo_b - x_lo_a)
    call add_compensated(s%work, s%work_lo, dot_product(scene%forcing%constant, dx))
    call add_compensated(s%friction_loss, s%friction_lo, -dot_product(mode%f_slide, dx))
  end subroutine book_constant_ledger

  !> Whether a stretch of this mode under constant forces has work or friction to book: not
  !> without a force and a sliding body (case 3 between impacts: adding zeros would change
  !> no bit).
  pure logical function books_ledger(scene, mode)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    books_ledger = any(scene%forcing%constant /= 0.0_wp) .or. any(mode%f_slide /= 0.0_wp)
  end function books_ledger

  !> One classical RK4 step of the mode's equations from a to b; the energy ledger by
  !> Simpson's rule on the step's Hermite velocity, exact where RK4 is (polynomial forcing).
  subroutine rk4_step(self, scene, mode, a, step, b)
    class(rk4_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(state_type), intent(inout) :: b     ! all of it is set (inout: no default init)
    real(wp) :: f0(2), fm(2), f1(2), a0(2), am(2), a1(2)
    real(wp) :: v0(2), vm(2)
    if (scene%springs%present) then
      call state_dependent_step(self, scene, mode, a, step, b)
      return
    end if
    b = a
    if (self%constant_forcing) then
      ! The mode's acceleration was worked out once, at the event point.
      call self%advance_constant(b, step)
      call book_constant_ledger(scene, mode, a%x, a%x_lo, b%x, b%x_lo, b)
      return
    end if
    ! A step's end force is the next step's start force: evaluated once (a sine costs).
    call add_compensated(b%t, b%t_lo, step)
    if (a%t == self%end_force_t) then
      f0 = self%end_force
    else
      f0 = scene%forcing%force(a%t)
    end if
    fm = scene%forcing%force(a%t + 0.5_wp * step)
    f1 = scene%forcing%force(b%t)
    self%end_force_t = b%t
    self%end_force = f1
    ! Within a mode the acceleration depends on time only, so stages 2 and 3 share it.
    a0 = mode%acceleration(f0)
    am = mode%acceleration(fm)
    a1 = mode%acceleration(f1)
    ! RK4's stages collapse (the acceleration does not depend on the state): x gains
    ! h v + h^2/6 (a0 + 2 am) and v gains h/6 (a0 + 4 am + a1).
    v0 = a%v + a%v_lo
    call add_compensated(b%x, b%x_lo, step * (v0 + (step / 6.0_wp) * (a0 + 2.0_wp * am)))
    call add_compensated(b%v, b%v_lo, (step / 6.0_wp) * (a0 + 4.0_wp * am + a1))
    vm = 0.5_wp * (a%v + b%v) + 0.125_wp * step * (a0 - a1)
    call add_compensated(b%work, b%work_lo, step / 6.0_wp * (dot_product(f0, a%v) + &
      4.0_wp * dot_product(fm, vm) + dot_product(f1, b%v)))
    call add_compensated(b%friction_loss, b%friction_lo, step / 6.0_wp * &
      dot_product(-mode%f_slide, a%v + 4.0_wp * vm + b%v))
  end subroutine rk4_step

  !> One classical RK4 step when the forces depend on the state (springs, dampers): the four
  !> stages in full, a = gain (F(t, x, v) + f_slide) within the mode. The ledger as for
  !> time-only forces, by Simpson's rule on the step's Hermite velocity (order 4): the external
  !> forces' work, the sliding friction's loss and the dampers' dissipation.
  subroutine state_dependent_step(self, scene, mode, a, step, b)
    class(rk4_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(state_type), intent(inout) :: b
    real(wp) :: kx(2, 4), kv(2, 4), v0(2), v1(2), vm(2), f(2), acc_end(2), half
    ! The external forces at the step's start, middle and end (stages 2 and 3 share the
    ! middle's): evaluated once each and used by the stages and by the work's quadrature.
    real(wp) :: f0(2), fm(2), f1(2)
    half = 0.5_wp * step
    v0 = a%v + a%v_lo
    if (a%t == self%end_force_t .and. all(a%x == self%end_x) .and. all(a%x_lo == self%end_x_lo) &
        .and. all(a%v == self%end_v) .and. all(a%v_lo == self%end_v_lo)) then
      f0 = self%end_external
      f = self%end_force
    else
      f0 = scene%forcing%force(a%t)
      f = f0 + scene%springs%force(a%x, a%x_lo, v0)
    end if
    fm = scene%forcing%force(a%t + half)
    f1 = scene%forcing%force(a%t + step)
    kx(:, 1) = v0
    kv(:, 1) = mode%acceleration(f)
    kx(:, 2) = v0 + half * kv(:, 1)
    kv(:, 2) = mode%acceleration(fm + scene%springs%force(a%x, a%x_lo + half * kx(:, 1), kx(:, 2)))
    kx(:, 3) = v0 + half * kv(:, 2)
    kv(:, 3) = mode%acceleration(fm + scene%springs%force(a%x, a%x_lo + half * kx(:, 2), kx(:, 3)))
    kx(:, 4) = v0 + step * kv(:, 3)
    kv(:, 4) = mode%acceleration(f1 + scene%springs%force(a%x, a%x_lo + step * kx(:, 3), kx(:, 4)))
    b = a
    call add_compensated(b%t, b%t_lo, step)
    call add_compensated(b%x, b%x_lo, (step / 6.0_wp) * (kx(:, 1) + 2.0_wp * (kx(:, 2) + kx(:, 3)) + kx(:, 4)))
    call add_compensated(b%v, b%v_lo, (step / 6.0_wp) * (kv(:, 1) + 2.0_wp * (kv(:, 2) + kv(:, 3)) + kv(:, 4)))
    ! The end force is the next step's start force.
    v1 = b%v + b%v_lo
    f = f1 + scene%springs%force(b%x, b%x_lo, v1)
    self%end_external = f1
    self%end_force = f
    self%end_force_t = b%t
    self%end_x = b%x
    self%end_x_lo = b%x_lo
    self%end_v = b%v
    self%end_v_lo = b%v_lo
    acc_end = mode%acceleration(f)
    vm = 0.5_wp * (v0 + v1) + 0.125_wp * step * (kv(:, 1) - acc_end)
    call add_compensated(b%work, b%work_lo, step / 6.0_wp * (dot_product(f0, v0) + &
      4.0_wp * dot_product(fm, vm) + dot_product(f1, v1)))
    if (any(mode%f_slide /= 0.0_wp)) call add_compensated(b%friction_loss, b%friction_lo, step / 6.0_wp * &
      dot_product(-mode%f_slide, v0 + 4.0_wp * vm + v1))
    if (scene%springs%has_damper) call add_compensated(b%damping_loss, b%damping_lo, step / 6.0_wp * &
      (scene%springs%damping_power(v0) + 4.0_wp * scene%springs%damping_power(vm) + &
      scene%springs%damping_power(v1)))
  end subroutine state_dependent_step

  !> The step's dense output: Hermite coefficients of both bodies' displacements.
  pure function dense_output(a, b, step) result(c)
    type(state_type), intent(in) :: a, b
    real(wp), intent(in) :: step
    real(wp) :: c(3, 2)
    c(:, 1) = hermite((b%x(1) - a%x(1)) + (b%x_lo(1) - a%x_lo(1)), a%v(1), b%v(1), step)
    c(:, 2) = hermite((b%x(2) - a%x(2)) + (b%x_lo(2) - a%x_lo(2)), a%v(2), b%v(2), step)
  end function dense_output
end module impact1d_stepping
