!> Stepping within a mode (METHOD.md 3): the classical RK4 step, its closed form under
!> constant forces, the exact ledger over such steps, and the step's dense output.
module impact1d_stepping
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  use impact1d_modes, only: mode_type
  use impact1d_events, only: hermite
  use impact1d_lanes, only: max_lanes
  use impact1d_state, only: lane_state_type, add_compensated, constant_step, constant_steps
  use impact1d_loads, only: stop_release_loss
  use impact1d_springs, only: springs_type
  implicit none
  private
  public :: rk4_type, book_constant_ledger, books_ledger, dense_output

  !> What the integrator keeps between steps, in lanes (impact1d_lanes' max_lanes: a lane past
  !> N idle at 0).
  type :: rk4_type
    !> No table, no sine: the forces are constant and so is each mode's acceleration.
    logical :: constant_forcing = .false.
    !> Tables and constants: the dense output is exact, so no root can be missed.
    logical :: polynomial_forcing = .false.
    !> The mode's acceleration under constant forces, worked out once at the event point.
    real(wp) :: constant_acceleration(max_lanes) = 0.0_wp
    !> The force at the end of the last step taken, and when: the next step's start force.
    real(wp) :: end_force(max_lanes) = 0.0_wp, end_force_t = -huge(1.0_wp)
    !> With springs the force depends on the state too: the state it was evaluated in.
    real(wp), dimension(max_lanes) :: end_x = 0.0_wp, end_x_lo = 0.0_wp, end_v = 0.0_wp, end_v_lo = 0.0_wp
    real(wp) :: end_external(max_lanes) = 0.0_wp   !< and its external (time-only) part
    !> The springs and dampers the state-dependent step applies: the scene's, then the
    !> compliant stops engaged as elements of their own (set_springs, at the run's start
    !> and whenever a stop switches), so a scene without stops steps exactly as before.
    !> Allocatable (once a run): a component of its size default-initialised in run made
    !> run too large for the compiler to inline advance (+50 instructions a spring step).
    type(springs_type), allocatable :: springs
    !> impact1d_state's constant_steps, called through this pointer (set by run) so that the
    !> compiler does not inline it: compiled on its own its loop keeps every value in
    !> registers, two bodies a register (2.6 ns a step); inlined, it takes the registers its
    !> caller leaves, and an unrelated change to the caller once spilled half of them (4.3 ns).
    procedure(constant_steps), pointer, nopass :: bulk_steps => null()
  contains
    procedure :: step => rk4_step
    procedure :: set_springs
  end type rk4_type

contains

  !> Under constant forces the work and the friction loss over any stretch of one mode are
  !> the forces times the displacement, exactly (no quadrature): from x_a to x_b, into the
  !> ledger (work, friction_loss with their low parts).
  pure subroutine book_constant_ledger(scene, mode, x_a, x_lo_a, x_b, x_lo_b, work, work_lo, friction_loss, &
      friction_lo)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    real(wp), dimension(max_lanes), intent(in) :: x_a, x_lo_a, x_b, x_lo_b   !< in lanes
    real(wp), intent(inout) :: work, work_lo, friction_loss, friction_lo
    real(wp) :: dx(max_lanes)
    if (.not. books_ledger(scene, mode)) return
    dx = (x_b - x_a) + (x_lo_b - x_lo_a)
    call add_compensated(work, work_lo, dot_product(scene%forcing%constant_lanes, dx))
    call add_compensated(friction_loss, friction_lo, -dot_product(mode%f_slide, dx))
  end subroutine book_constant_ledger

  !> Whether a stretch of this mode under constant forces has work or friction to book: not
  !> without a force and a sliding body (case 3 between impacts: adding zeros would change
  !> no bit).
  pure logical function books_ledger(scene, mode)
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    books_ledger = any(scene%forcing%constant_lanes /= 0.0_wp) .or. any(mode%f_slide /= 0.0_wp)
  end function books_ledger

  !> One classical RK4 step of the mode's equations from a to b (states in lanes: an idle
  !> lane adds +0 to the ledger's sums); the energy ledger by Simpson's rule on the step's
  !> Hermite velocity, exact where RK4 is (polynomial forcing).
  subroutine rk4_step(self, scene, mode, a, step, b)
    class(rk4_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    type(mode_type), intent(in) :: mode
    type(lane_state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(lane_state_type), intent(inout) :: b     ! all of it is set (inout: no default init)
    real(wp), dimension(max_lanes) :: f0, fm, f1, a0, am, a1, v0, vm
    if (scene%springs%present) then
      call state_dependent_step(self, scene, mode, a, step, b)
      return
    end if
    b = a
    if (self%constant_forcing) then
      ! The mode's acceleration was worked out once, at the event point.
      call add_compensated(b%t, b%t_lo, step)
      call constant_step(step, self%constant_acceleration, b%x, b%x_lo, b%v, b%v_lo)
      call book_constant_ledger(scene, mode, a%x, a%x_lo, b%x, b%x_lo, b%work, b%work_lo, b%friction_loss, &
        b%friction_lo)
      return
    end if
    ! A step's end force is the next step's start force: evaluated once (a sine costs).
    call add_compensated(b%t, b%t_lo, step)
    if (a%t == self%end_force_t) then
      f0 = self%end_force
    else
      call scene%forcing%force(a%t, f0)
    end if
    call scene%forcing%force(a%t + 0.5_wp * step, fm)
    call scene%forcing%force(b%t, f1)
    self%end_force_t = b%t
    self%end_force = f1
    ! Within a mode the acceleration depends on time only, so stages 2 and 3 share it.
    call mode%acceleration(f0, a0)
    call mode%acceleration(fm, am)
    call mode%acceleration(f1, a1)
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
    type(lane_state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(lane_state_type), intent(inout) :: b     ! all of it is set (inout: no default init)
    real(wp) :: half
    real(wp), dimension(max_lanes) :: v0, v1, vm, f, load, acc_end, dx
    real(wp), dimension(max_lanes) :: kx1, kx2, kx3, kx4, kv1, kv2, kv3, kv4
    ! The external forces at the step's start, middle and end (stages 2 and 3 share the
    ! middle's): evaluated once each and used by the stages and by the work's quadrature.
    real(wp), dimension(max_lanes) :: f0, fm, f1
    half = 0.5_wp * step
    v0 = a%v + a%v_lo
    if (a%t == self%end_force_t .and. all(a%x == self%end_x) .and. all(a%x_lo == self%end_x_lo) &
        .and. all(a%v == self%end_v) .and. all(a%v_lo == self%end_v_lo)) then
      f0 = self%end_external
      f = self%end_force
    else
      call scene%forcing%force(a%t, f0)
      f = f0
      call self%springs%add_force(a%x, a%x_lo, v0, f)
    end if
    call scene%forcing%force(a%t + half, fm)
    call scene%forcing%force(a%t + step, f1)
    ! The stages: velocities kx, accelerations kv (each stage's displacement named: an
    ! expression as an argument was packed at each call).
    kx1 = v0
    call mode%acceleration(f, kv1)
    kx2 = v0 + half * kv1
    dx = a%x_lo + half * kx1
    load = fm
    call self%springs%add_force(a%x, dx, kx2, load)
    call mode%acceleration(load, kv2)
    kx3 = v0 + half * kv2
    dx = a%x_lo + half * kx2
    load = fm
    call self%springs%add_force(a%x, dx, kx3, load)
    call mode%acceleration(load, kv3)
    kx4 = v0 + step * kv3
    dx = a%x_lo + step * kx3
    load = f1
    call self%springs%add_force(a%x, dx, kx4, load)
    call mode%acceleration(load, kv4)
    b = a
    call add_compensated(b%t, b%t_lo, step)
    call add_compensated(b%x, b%x_lo, (step / 6.0_wp) * (kx1 + 2.0_wp * (kx2 + kx3) + kx4))
    call add_compensated(b%v, b%v_lo, (step / 6.0_wp) * (kv1 + 2.0_wp * (kv2 + kv3) + kv4))
    ! The end force is the next step's start force.
    v1 = b%v + b%v_lo
    f = f1
    call self%springs%add_force(b%x, b%x_lo, v1, f)
    self%end_external = f1
    self%end_force = f
    self%end_force_t = b%t
    self%end_x = b%x
    self%end_x_lo = b%x_lo
    self%end_v = b%v
    self%end_v_lo = b%v_lo
    call mode%acceleration(f, acc_end)
    vm = 0.5_wp * (v0 + v1) + 0.125_wp * step * (kv1 - acc_end)
    call add_compensated(b%work, b%work_lo, step / 6.0_wp * (dot_product(f0, v0) + &
      4.0_wp * dot_product(fm, vm) + dot_product(f1, v1)))
    if (any(mode%f_slide /= 0.0_wp)) call add_compensated(b%friction_loss, b%friction_lo, step / 6.0_wp * &
      dot_product(-mode%f_slide, v0 + 4.0_wp * vm + v1))
    if (self%springs%has_damper) call add_compensated(b%damping_loss, b%damping_lo, step / 6.0_wp * &
      (self%springs%damping_power(v0) + 4.0_wp * self%springs%damping_power(vm) + &
      self%springs%damping_power(v1)))
    ! The stops released inside lose their stored energy exactly (the engaged ones are
    ! dampers of self%springs above).
    if (scene%n_stops > 0 .and. self%springs%has_damper) call add_compensated(b%damping_loss, b%damping_lo, &
      stop_release_loss(scene, mode%engaged, a%x, a%x_lo, b%x, b%x_lo))
  end subroutine state_dependent_step

  !> The springs the state-dependent step applies: the scene's, and each compliant stop
  !> engaged (bits of engaged) as a spring and damper along its row's normal with its rest
  !> at the limit (tension k gap + c gap', pulling the ends together: the stop's push F =
  !> -(k gap + c gap')). The step's cached end force is forgotten (the forces changed).
  pure subroutine set_springs(self, scene, engaged)
    class(rk4_type), intent(inout) :: self
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: engaged
    integer :: j, r, n
    self%springs = scene%springs
    self%end_force_t = -huge(1.0_wp)
    n = self%springs%n
    do j = 1, scene%n_stops
      if (.not. btest(engaged, j - 1)) cycle
      r = scene%n_rows + j
      n = n + 1
      self%springs%body(:, n) = scene%row_body(:, r)
      self%springs%normal(:, n) = scene%pair%normal(:, r)
      self%springs%k(n) = scene%row_k(r)
      self%springs%c(n) = scene%row_c(r)
      self%springs%rest(n) = -scene%row_offset(r)
    end do
    self%springs%n = n
  end subroutine set_springs

  !> The step's dense output: Hermite coefficients of each body's displacement (lanes).
  pure subroutine dense_output(a, b, step, c)
    type(lane_state_type), intent(in) :: a, b
    real(wp), intent(in) :: step
    real(wp), intent(out) :: c(3, max_lanes)
    integer :: i
    do i = 1, max_lanes
      c(:, i) = hermite((b%x(i) - a%x(i)) + (b%x_lo(i) - a%x_lo(i)), a%v(i), b%v(i), step)
    end do
  end subroutine dense_output
end module impact1d_stepping
