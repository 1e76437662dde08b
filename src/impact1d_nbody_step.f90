!> Stepping and event location of the N-body engine (METHOD.md 3-4; docs/method.md section
!> 9): the classical RK4 step of N bodies within a mode, its energy ledger, the rows' exact
!> gaps, and the earliest event inside a step (a gap closing, a sliding body stopping, the
!> mode's conditions failing) on the step's Hermite dense output. The state is N-long
!> (impact1d_state's state_type), for any N.
module impact1d_nbody_step
  use impact1d_kinds, only: wp, eps_wp
  use impact1d_scene, only: scene_type
  use impact1d_state, only: state_type, add_compensated, product_error, copy_scalars
  use impact1d_events, only: hermite, earliest_crossing, stop_force_cubic
  use impact1d_yardsticks, only: gap_rounding, velocity_rounding, time_rounding
  use impact1d_elements, only: add_element_forces, add_moving_element_forces, add_element_rates, element_damping_power, &
    add_stop_forces, add_stop_rates, stop_damping_power, stop_release_loss, stop_drive_power
  use impact1d_body_mode, only: body_mode_type, mode_work_type, solve_body_mode, same_mode, mode_solved, &
    drive_accelerations, shift_to_drives, relative_velocity
  use impact1d_friction_laws, only: slip, add_stribeck_forces, law_powers, contact_loss, belt_speed, belt_rate, &
    belt_moving, belt_displacement, shift_to_belts, belt_accelerations
  implicit none
  private
  public :: nbody_force, nbody_rate, nbody_step, row_gap, row_velocity, row_gap_tolerance, locate_nbody, &
    refine_nbody, gaps_hold, mode_acceleration, ground_motion, row_abs, mode_crossing, clock_to_stop, &
    clock_to_belts
  public :: found_none, found_row, found_body, found_hold, found_stop, found_friction, stop_gap_band, stop_force_band

  !> What a location found: a row's gap closing (a compliant stop's too: its engagement), a
  !> sliding body stopping, the mode failing, a compliant stop's force crossing zero (its
  !> release, or its engagement again while still inside), a friction contact between bodies
  !> (&friction) coming to relative rest.
  integer, parameter :: found_none = 0, found_row = 1, found_body = 2, found_hold = 3, found_stop = 4, &
    found_friction = 5

  !> A step's end forces kept for the next step's first stage (the two-body engine's
  !> end_force, FSAL-like): the external forces at the end's time t and the mode's
  !> accelerations under all the applied forces there. Two slots: the run's state's
  !> (`now`) and the end of the step last taken from it (3 - now), which becomes the run's
  !> when advance takes that step (`accept`). A step that computed its first stage itself
  !> keeps it in the run's slot too, for its retries and refinements from the same state and
  !> for the location's external forces there. A slot is used only at its own time t and
  !> while valid: whatever changes the state or the mode without a step (an event point)
  !> calls `forget`. Kept where the stages' forces are the external and the elements' only
  !> (not scene%stage_powers): the same inputs and arithmetic as the stage it replaces.
  !> nbody_step works in the slots themselves (no copies in or out); under
  !> scene%stage_powers they are its scratch, never valid. Where the external forces are
  !> constants (no table, no sine: `timeless`) a slot holds at any time: the end's forces
  !> serve the next step also where the compensated clock's b%t is not a%t + step (a third
  !> of the steps; under forces that vary, f(b%t) differs from f(a%t + step) in its last
  !> bits, and a slot keyed on its time is all that keeps the bits).
  type, public :: kept_forces_type
    integer :: now = 1
    logical :: valid(2) = .false.
    logical :: timeless = .false.
    real(wp) :: t(2) = 0.0_wp
    real(wp), allocatable :: f(:, :), acc(:, :)      !< (N, 2)
  contains
    procedure :: reserve => reserve_kept
    procedure :: accept => accept_kept
    procedure :: forget => forget_kept
    procedure :: holds => kept_holds
  end type kept_forces_type

  !> The belts of sine speed's work in the hot procedures, called through pointers (set
  !> here, never assigned): inlined, or called directly, they changed what the compiler
  !> inlined around them, and scenes without such a belt paid (callgrind, the CLI's run:
  !> input/stick_slip.nml on the N-body engine +1.1%, drill_string.nml +1.3%; through the
  !> pointers -0.4% and +0.6%).
  abstract interface
    pure subroutine belt_hold_if(scene, mode, a, step, b)
      import :: scene_type, body_mode_type, state_type, wp
      type(scene_type), intent(in) :: scene
      type(body_mode_type), intent(in) :: mode
      type(state_type), intent(in) :: a
      real(wp), intent(in) :: step
      type(state_type), intent(inout) :: b
    end subroutine belt_hold_if
    pure subroutine less_belt_if(scene, i, sgn, t, step, p, q)
      import :: scene_type, wp
      type(scene_type), intent(in) :: scene
      integer, intent(in) :: i
      real(wp), intent(in) :: sgn, t, step
      real(wp), intent(inout) :: p(0:3), q(0:3)
    end subroutine less_belt_if
    pure subroutine belt_acc_if(scene, stuck, t, order, a)
      import :: scene_type, wp
      type(scene_type), intent(in) :: scene
      logical, intent(in) :: stuck(:)
      real(wp), intent(in) :: t
      integer, intent(in) :: order
      real(wp), intent(inout) :: a(:)
    end subroutine belt_acc_if
  end interface
  procedure(belt_hold_if), pointer :: belt_hold => hold_to_belts
  procedure(less_belt_if), pointer :: belt_less => less_belt
  procedure(belt_acc_if), pointer :: belt_acc => belt_accelerations

contains

  !> The slots of n bodies, both empty (the run's one allocation of them); timeless: the
  !> external forces are constants.
  pure subroutine reserve_kept(self, n, timeless)
    class(kept_forces_type), intent(inout) :: self
    integer, intent(in) :: n
    logical, intent(in) :: timeless
    if (allocated(self%f)) deallocate(self%f, self%acc)
    allocate(self%f(n, 2), self%acc(n, 2))
    self%timeless = timeless
    call self%forget()
  end subroutine reserve_kept

  !> The step last taken is the run's state now: its end's slot becomes the start's.
  pure subroutine accept_kept(self)
    class(kept_forces_type), intent(inout) :: self
    self%now = 3 - self%now
    self%valid(3 - self%now) = .false.
  end subroutine accept_kept

  !> The state or the mode changed without a step: nothing kept holds.
  pure subroutine forget_kept(self)
    class(kept_forces_type), intent(inout) :: self
    self%valid = .false.
  end subroutine forget_kept

  !> Whether the run's slot holds the forces at time t (of the run's state).
  pure logical function kept_holds(self, t)
    class(kept_forces_type), intent(in) :: self
    real(wp), intent(in) :: t
    kept_holds = self%valid(self%now)
    if (kept_holds .and. .not. self%timeless) kept_holds = self%t(self%now) == t
  end function kept_holds

  !> Applied forces f (external and elements') at time t, positions x + dx, velocities v;
  !> engaged: the compliant stops engaged (a mode's; absent: none); external: the external
  !> forces at t when they are known (a kept step's).
  pure subroutine nbody_force(scene, t, x, dx, v, f, engaged, external)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t
    real(wp), contiguous, intent(in) :: x(:), dx(:), v(:)
    real(wp), contiguous, intent(out) :: f(:)
    logical, intent(in), optional :: engaged(:)
    real(wp), intent(in), optional :: external(:)
    if (present(external)) then
      f = external
    else
      call scene%forcing%force_all(t, f)
    end if
    if (.not. scene%springs%present) return
    ! (geared elements are the moving ones' loop too: add_moving_element_forces)
    if (scene%gap_terms) then
      call add_moving_element_forces(scene, x, dx, v, f, t)
    else
      call add_element_forces(scene, x, dx, v, f)
    end if
    ! (a still ground's stops ignore t)
    if (scene%n_stops > 0 .and. present(engaged)) call add_stop_forces(scene, engaged, x, dx, v, f, t)
  end subroutine nbody_force

  !> Accelerations a in the mode under applied forces f at time t: a body held to a moving
  !> ground moves with it (impact1d_body_mode's drive_accelerations), a stuck body with its
  !> accelerating belt (impact1d_friction_laws' belt_accelerations).
  pure subroutine mode_acceleration(scene, mode, t, f, a)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: t, f(:)
    real(wp), intent(out) :: a(:)
    ! (the geared groups tested first and apart: with their branch and its temporary inside,
    ! mode_acceleration was no longer inlined, input/drill_string.nml took 1.8% more
    ! instructions)
    if (scene%geared) then
      call geared_acceleration(mode, f, a)
      return
    end if
    call mode%acceleration(f, a)
    if (scene%drives%n > 0) call drive_accelerations(scene, mode, t, 2, a)
    if (scene%belt_moves) call belt_acc(scene, mode%stuck, t, 2, a)
  end subroutine mode_acceleration

  !> mode_acceleration of a geared scene's groups (docs/method.md section 14; no moving
  !> grounds with them).
  !> (Kept out of line: inlined, its temporary made mode_acceleration too big to inline.)
  pure subroutine geared_acceleration(mode, f, a)
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: f(:)
    real(wp), intent(out) :: a(:)
    call mode%geared_response(f + mode%f_slide, a)
  end subroutine geared_acceleration

  !> The part of row k's gap (order 0), its rate (1), acceleration (2) or jerk (3) at t
  !> that its moving ground end makes (0 for a row without one): the ground end's
  !> coefficient is -n_b, so the gap is n_b (x_b - w(t)) + offset.
  pure real(wp) function ground_motion(scene, k, t, order) result(g)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k, order
    real(wp), intent(in) :: t
    integer :: d
    g = 0.0_wp
    if (scene%drives%n == 0) return
    d = scene%row_drive(k)
    if (d == 0) return
    select case (order)
    case (0)
      g = scene%drives%position(d, t)
    case (1)
      g = scene%drives%velocity(d, t)
    case (2)
      g = scene%drives%acceleration(d, t)
    case default
      g = scene%drives%jerk(d, t)
    end select
    g = -scene%row_normal(2, k) * g
  end function ground_motion


  !> Right derivative df of the applied forces at time t, velocities v (engaged: as for
  !> nbody_force).
  pure subroutine nbody_rate(scene, t, v, df, engaged)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: t, v(:)
    real(wp), intent(out) :: df(:)
    logical, intent(in), optional :: engaged(:)
    call scene%forcing%rate(t, df)
    if (.not. scene%springs%present) return
    if (scene%drives%n > 0) then
      call add_element_rates(scene, v, df, t)
    else
      call add_element_rates(scene, v, df)
    end if
    if (scene%n_stops > 0 .and. present(engaged)) call add_stop_rates(scene, engaged, v, df, t)
  end subroutine nbody_rate

  !> Accelerations a in the mode under applied forces f at time t and velocities v, with
  !> Stribeck's part of sliding friction (impact1d_friction_laws) when the scene names it.
  !> (mode_acceleration written out here (a geared scene has no moving grounds): through
  !> it the compiler inlined the geared branch here and called the mode's acceleration,
  !> input/drill_string.nml 6 M instructions more, 1.4%.)
  pure subroutine law_acceleration(scene, mode, t, v, f, a)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: t, v(:)
    real(wp), intent(inout) :: f(:)
    real(wp), intent(out) :: a(:)
    if (scene%stribeck) call add_stribeck_forces(scene, mode%sgn, v, t, f)
    if (scene%geared) then
      call geared_acceleration(mode, f, a)
      return
    end if
    call mode%acceleration(f, a)
    if (scene%drives%n > 0) call drive_accelerations(scene, mode, t, 2, a)
    if (scene%belt_moves) call belt_acc(scene, mode%stuck, t, 2, a)
  end subroutine law_acceleration

  !> One classical RK4 step of the mode's equations from a to b (the four stages in full: the
  !> forces may depend on the state); the ledger by Simpson's rule on the step's Hermite
  !> velocity (external work, sliding friction's loss, dampers' dissipation), exact where
  !> RK4 is. With a friction law (belt_v, v_s, c_v) friction's loss and the belts' work are
  !> RK4's own quadrature of their power at the stages (law_ledger). The first stage's
  !> forces are kept's when it holds them for a (the last step's end, or a step already
  !> taken from a), and the end's go into kept for the next step. The stages' forces and
  !> accelerations live in kept's slots (the start's in slot now, the end's in 3 - now, valid
  !> only without scene%stage_powers), and the state's arithmetic runs body by body in one
  !> loop a stage (each body's operations in the order of the array statements they
  !> replace: the same bits; at small N each array statement was a loop of its own with its
  !> descriptor, or a call to memcpy). b has a's size (the run's trial state).
  subroutine nbody_step(scene, mode, a, step, b, kept)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(state_type), intent(inout) :: b
    type(kept_forces_type), intent(inout) :: kept
    real(wp), dimension(scene%n_bodies) :: v0, v1, vm, f, dx, kx2, kx3, kx4, kv2, kv3, kv4, fm
    real(wp) :: half, power(4), loss(4), belt(4)
    integer :: now, e, i
    half = 0.5_wp * step
    now = kept%now
    e = 3 - now
    do i = 1, scene%n_bodies
      v0(i) = a%v(i) + a%v_lo(i)
    end do
    if (.not. kept%holds(a%t)) then
      call scene%forcing%force_all(a%t, kept%f(:, now))
      if (scene%springs%present) dx = a%x_lo
      call stage(kept%f(:, now), v0, kept%acc(:, now), 0.0_wp, 1)
      ! (for the retries and refinements of this step, and the location)
      kept%t(now) = a%t
      kept%valid(now) = .not. scene%stage_powers
    end if
    kept%valid(e) = .false.
    call scene%forcing%force_all(a%t + half, fm)
    call scene%forcing%force_all(a%t + step, kept%f(:, e))
    call next_stage(kept%acc(:, now), v0, half, kx2)
    call stage(fm, kx2, kv2, half, 2)
    call next_stage(kv2, kx2, half, kx3)
    call stage(fm, kx3, kv3, half, 3)
    call next_stage(kv3, kx3, step, kx4)
    call stage(kept%f(:, e), kx4, kv4, step, 4)
    call step_state(kept%acc(:, now))
    if (scene%held_motion) then
      call hold_to_drives(scene, mode, a, step, b)
      v1 = b%v + b%v_lo
    end if
    ! (geared scenes take the stage_powers path, whose accelerations are mode_acceleration's)
    if (scene%stage_powers) then
      call drive_step_ledger(kept%f(:, e), kept%acc(:, e))
    else
      ! (stage 1's forces and arithmetic at b: the next step's first stage)
      if (scene%springs%present) then
        f = kept%f(:, e)
        call add_element_forces(scene, b%x, b%x_lo, v1, f)
        call mode%acceleration(f, kept%acc(:, e))
      else
        call mode%acceleration(kept%f(:, e), kept%acc(:, e))
      end if
      kept%t(e) = a%t + step
      kept%valid(e) = .true.
    end if
    call step_ledger(kept%f(:, now), kept%acc(:, now), kept%f(:, e), kept%acc(:, e))

  contains

    !> The next stage's velocities kx = v0 + tau kv and, with springs, its displacements
    !> dx = a%x_lo + tau kx_prev (kx_prev: the previous stage's velocities).
    subroutine next_stage(kv, kx_prev, tau, kx)
      real(wp), intent(in) :: kv(:), kx_prev(:), tau
      real(wp), intent(out) :: kx(:)
      if (scene%springs%present) then
        do i = 1, scene%n_bodies
          kx(i) = v0(i) + tau * kv(i)
          dx(i) = a%x_lo(i) + tau * kx_prev(i)
        end do
      else
        do i = 1, scene%n_bodies
          kx(i) = v0(i) + tau * kv(i)
        end do
      end if
    end subroutine next_stage

    !> b: a advanced by the step, RK4's sums of the stages (kv1: stage 1's accelerations),
    !> compensated; v1 its velocities.
    subroutine step_state(kv1)
      real(wp), intent(in) :: kv1(:)
      real(wp) :: hi, lo
      call copy_scalars(b, a)
      call add_compensated(b%t, b%t_lo, step)
      do i = 1, scene%n_bodies
        hi = a%x(i)
        lo = a%x_lo(i)
        call add_compensated(hi, lo, (step / 6.0_wp) * (v0(i) + 2.0_wp * (kx2(i) + kx3(i)) + kx4(i)))
        b%x(i) = hi
        b%x_lo(i) = lo
        hi = a%v(i)
        lo = a%v_lo(i)
        call add_compensated(hi, lo, (step / 6.0_wp) * (kv1(i) + 2.0_wp * (kv2(i) + kv3(i)) + kv4(i)))
        b%v(i) = hi
        b%v_lo(i) = lo
        v1(i) = hi + lo
      end do
    end subroutine step_state

    !> The step's ledger: the external forces' work (f0, fm, f1 at the start, the middle
    !> and the end) and sliding friction's loss by Simpson's rule on the Hermite velocity
    !> (kv1, acc_end: the start's and the end's accelerations), the dampers' and the stops'.
    subroutine step_ledger(f0, kv1, f1, acc_end)
      real(wp), intent(in) :: f0(:), kv1(:), f1(:), acc_end(:)
      real(wp) :: power0, power_m, power1, slide_loss
      logical :: sliding
      power0 = 0.0_wp
      power_m = 0.0_wp
      power1 = 0.0_wp
      slide_loss = 0.0_wp
      sliding = .false.
      ! (each sum in the order of the dot_product it replaces)
      do i = 1, scene%n_bodies
        vm(i) = 0.5_wp * (v0(i) + v1(i)) + 0.125_wp * step * (kv1(i) - acc_end(i))
        power0 = power0 + f0(i) * v0(i)
        power_m = power_m + fm(i) * vm(i)
        power1 = power1 + f1(i) * v1(i)
        slide_loss = slide_loss + (-mode%f_slide(i)) * (v0(i) + 4.0_wp * vm(i) + v1(i))
        sliding = sliding .or. mode%f_slide(i) /= 0.0_wp
      end do
      call add_compensated(b%work, b%work_lo, step / 6.0_wp * (power0 + 4.0_wp * power_m + power1))
      if (scene%belts .or. scene%stribeck) then
        call law_ledger()
      else if (sliding) then
        call add_compensated(b%friction_loss, b%friction_lo, step / 6.0_wp * slide_loss)
      end if
      if (scene%gap_terms) then
        if (scene%springs%present) call add_compensated(b%damping_loss, b%damping_lo, step / 6.0_wp * &
          (element_damping_power(scene, v0, a%t) + 4.0_wp * element_damping_power(scene, vm, a%t + half) + &
          element_damping_power(scene, v1, drive_time(a%t, step))))
      else if (scene%springs%present) then
        call add_compensated(b%damping_loss, b%damping_lo, step / 6.0_wp * &
          (element_damping_power(scene, v0) + 4.0_wp * element_damping_power(scene, vm) + &
          element_damping_power(scene, v1)))
      end if
      if (scene%n_stops > 0 .and. scene%springs%has_damper) call stop_ledger()
    end subroutine step_ledger

    !> Stage k's accelerations acc at external forces fx, positions a%x + dx (dx: the
    !> caller's, with springs), velocities v, time a%t + tau (moving grounds and compliant
    !> stops apart: moving_stage; tested as one sum, since a second test here, or the stops'
    !> forces below, and the compiler no longer inlined stage: input/train.nml's run took
    !> 1.5% more instructions).
    subroutine stage(fx, v, acc, tau, k)
      real(wp), intent(in) :: fx(:), v(:), tau
      real(wp), intent(out) :: acc(:)
      integer, intent(in) :: k
      if (scene%stage_powers) then
        call moving_stage(fx, v, acc, drive_time(a%t, tau), power(k), k)
        return
      end if
      if (scene%springs%present) then
        f = fx
        call add_element_forces(scene, a%x, dx, v, f)
        call mode%acceleration(f, acc)
      else
        call mode%acceleration(fx, acc)
      end if
    end subroutine stage

    !> stage with moving grounds, compliant stops or a friction law at time t: and the power
    !> the grounds put in (a still ground's element ends are at w = 0 here, the same bits);
    !> with a friction law, friction's loss and the belts' power (loss(k), belt(k)).
    subroutine moving_stage(fx, v, acc, t, drive_power, k)
      real(wp), intent(in) :: fx(:), v(:), t
      real(wp), intent(out) :: acc(:), drive_power
      integer, intent(in) :: k
      f = fx
      drive_power = 0.0_wp
      if (scene%springs%present) then
        call add_moving_element_forces(scene, a%x, dx, v, f, t, drive_power)
        if (scene%n_stops > 0) then
          call add_stop_forces(scene, mode%engaged, a%x, dx, v, f, t)
          drive_power = drive_power + stop_drive_power(scene, mode%engaged, a%x, dx, v, t)
        end if
      end if
      call law_acceleration(scene, mode, t, v, f, acc)
      drive_power = drive_power + held_drive_power(scene, mode, t, f, acc)
      if (scene%belts .or. scene%stribeck) call law_powers(scene, mode%f_slide, mode%sgn, mode%group, &
        mode%drive, f, v, t, loss(k), belt(k))
      if ((scene%belts .or. scene%stribeck) .and. scene%n_frictions > 0) &
        loss(k) = loss(k) + contact_loss(scene, mode%friction_sgn, v)
    end subroutine moving_stage

    !> The time a + tau at which the stage sees the drives (a table's corner at the step's
    !> end: just before it, impact1d_drives' before_corner).
    pure real(wp) function drive_time(t, tau)
      real(wp), intent(in) :: t, tau
      drive_time = t + tau
      if (scene%drives%tables) drive_time = scene%drives%before_corner(t, drive_time)
    end function drive_time

    !> Friction's loss and the belts' work over the step, by RK4's quadrature of the stages'
    !> powers (impact1d_friction_laws' law_powers).
    subroutine law_ledger()
      call add_compensated(b%friction_loss, b%friction_lo, step / 6.0_wp * (loss(1) + 2.0_wp * (loss(2) + &
        loss(3)) + loss(4)))
      if (scene%belts) call add_compensated(b%drive_work, b%drive_lo, step / 6.0_wp * (belt(1) + &
        2.0_wp * (belt(2) + belt(3)) + belt(4)))
    end subroutine law_ledger

    !> The step's end with moving grounds, compliant stops or a friction law (moving_stage):
    !> the accelerations there, and the work the prescribed motion did, by RK4's own
    !> quadrature of the stages' power (0 without moving grounds). f1: the external forces
    !> at the end, acc_end: the accelerations there.
    subroutine drive_step_ledger(f1, acc_end)
      real(wp), intent(in) :: f1(:)
      real(wp), intent(out) :: acc_end(:)
      real(wp) :: t_end
      f = f1
      t_end = b%t
      if (scene%drives%tables) t_end = drive_time(a%t, step)
      if (scene%springs%present) call add_moving_element_forces(scene, b%x, b%x_lo, v1, f, t_end)
      if (scene%n_stops > 0) call add_stop_forces(scene, mode%engaged, b%x, b%x_lo, v1, f, t_end)
      call law_acceleration(scene, mode, t_end, v1, f, acc_end)
      call add_compensated(b%drive_work, b%drive_lo, step / 6.0_wp * (power(1) + 2.0_wp * (power(2) + &
        power(3)) + power(4)))
    end subroutine drive_step_ledger

    !> The compliant stops' losses over the step: the engaged ones' dampers by Simpson's
    !> rule, as the elements'; those released inside lose their stored energy exactly.
    subroutine stop_ledger()
      call add_compensated(b%damping_loss, b%damping_lo, step / 6.0_wp * &
        (stop_damping_power(scene, mode%engaged, v0, a%t) + 4.0_wp * stop_damping_power(scene, mode%engaged, &
        vm, a%t + half) + stop_damping_power(scene, mode%engaged, v1, drive_time(a%t, step))) + &
        stop_release_loss(scene, mode%engaged, a%x, a%x_lo, b%x, b%x_lo, a%t, b%t))
    end subroutine stop_ledger
  end subroutine nbody_step

  !> Bodies held to a moving ground move with it exactly over the step from a to b (by w(t +
  !> step) - w(t), at w'(t + step), a table's slope before a corner there): RK4's quadrature
  !> of w'' would leave their held rows' normal velocity off zero by its error, which the
  !> event points would take for impacts. Stuck bodies on accelerating belts likewise
  !> (hold_to_belts).
  pure subroutine hold_to_drives(scene, mode, a, step, b)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(state_type), intent(inout) :: b
    integer :: i
    do i = 1, scene%n_bodies
      if (mode%drive(i) == 0) cycle
      associate (d => mode%drive(i))
        b%x(i) = a%x(i)
        b%x_lo(i) = a%x_lo(i)
        call move_with_drive(scene, d, a%t, step, b%x(i), b%x_lo(i))
        b%v(i) = scene%drives%velocity(d, scene%drives%before_corner(a%t, a%t + step))
        b%v_lo(i) = 0.0_wp
      end associate
    end do
    ! (one test in nbody_step for both: a second cost the RK4 step of scenes without either)
    if (scene%belt_moves) call belt_hold(scene, mode, a, step, b)
  end subroutine hold_to_drives

  !> Stuck bodies on accelerating belts move with them exactly over the step from a to b (by
  !> the belt's displacement, at V(b%t), the clock the event point reads their slip at):
  !> RK4's quadrature of V' would leave them slipping by its error (hold_to_drives for a
  !> moving ground). The part m V' of the belt's force on such a body does the work of its
  !> kinetic energy, booked here exactly (law_powers books the rest, -(f + f_slide) V, by the
  !> stages' quadrature; RK4's quadrature of m V' V was off by 4e-4 J over 2 s at w dt = 0.6).
  pure subroutine hold_to_belts(scene, mode, a, step, b)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: step
    type(state_type), intent(inout) :: b
    integer :: i
    do i = 1, scene%n_bodies
      if (.not. (mode%stuck(i) .and. belt_moving(scene, i))) cycle
      b%x(i) = a%x(i)
      b%x_lo(i) = a%x_lo(i)
      call add_compensated(b%x(i), b%x_lo(i), belt_displacement(scene, i, a%t, step))
      b%v(i) = belt_speed(scene, i, b%t)
      b%v_lo(i) = 0.0_wp
      call add_compensated(b%drive_work, b%drive_lo, 0.5_wp * scene%body_mass(i) * (b%v(i)**2 - a%v(i)**2))
    end do
  end subroutine hold_to_belts

  !> The clock of s set to a stop t_stop a rounding away from t + t_lo (the run's step to a
  !> stop): the bodies held to moving grounds moved by the same rounding with them, or they
  !> would stand off their grounds' w(t), which is formed at the clock (a ball resting on a
  !> floor at -0.1 m/s stood 5e-21 m above it after 100 stops, not closed on it when
  !> another ball landed).
  pure subroutine clock_to_stop(scene, mode, t_stop, s)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: t_stop
    type(state_type), intent(inout) :: s
    real(wp) :: late
    integer :: i
    if (scene%drives%n > 0) then
      late = (t_stop - s%t) - s%t_lo
      do i = 1, scene%n_bodies
        if (mode%drive(i) > 0) call move_with_drive(scene, mode%drive(i), s%t, late, s%x(i), s%x_lo(i))
      end do
    end if
    s%t = t_stop
    s%t_lo = 0.0_wp
  end subroutine clock_to_stop

  !> clock_to_stop's move for the stuck bodies on accelerating belts (called before it, by
  !> the run: apart, it costs the scenes without such belts nothing): by the belt's
  !> displacement over the rounding, at V(t_stop) (the belt's work, as
  !> hold_to_belts books it).
  pure subroutine clock_to_belts(scene, mode, t_stop, s)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: t_stop
    type(state_type), intent(inout) :: s
    real(wp) :: late
    integer :: i
    late = (t_stop - s%t) - s%t_lo
    do i = 1, scene%n_bodies
      if (.not. (mode%stuck(i) .and. belt_moving(scene, i))) cycle
      call add_compensated(s%x(i), s%x_lo(i), belt_displacement(scene, i, s%t, late))
      call add_compensated(s%drive_work, s%drive_lo, 0.5_wp * scene%body_mass(i) * &
        (belt_speed(scene, i, t_stop)**2 - s%v(i)**2))
      s%v(i) = belt_speed(scene, i, t_stop)
      s%v_lo(i) = 0.0_wp
    end do
  end subroutine clock_to_belts

  !> x + x_lo moved by drive d's w(t + h) - w(t), its v h without rounding (a body held to a
  !> ground moving at constant speed stays on w as position_parts forms it at the clock).
  pure subroutine move_with_drive(scene, d, t, h, x, x_lo)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: d
    real(wp), intent(in) :: t, h
    real(wp), intent(inout) :: x, x_lo
    real(wp) :: dw, dw_lo
    call scene%drives%displacement_parts(d, t, h, dw, dw_lo)
    call add_compensated(x, x_lo, dw)
    if (dw_lo /= 0.0_wp) call add_compensated(x, x_lo, dw_lo)
  end subroutine move_with_drive

  !> Power a moving ground puts in through the rows that hold bodies to it: on each such body
  !> the rows' force m a - f - f_slide, at the ground's velocity (rows between the bodies it
  !> holds pass forces that cancel).
  pure real(wp) function held_drive_power(scene, mode, t, f, acc) result(power)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(in) :: t, f(:), acc(:)
    integer :: i
    power = 0.0_wp
    do i = 1, scene%n_bodies
      if (mode%drive(i) == 0) cycle
      power = power + (scene%body_mass(i) * acc(i) - (f(i) + mode%f_slide(i))) * &
        scene%drives%velocity(mode%drive(i), t)
    end do
  end function held_drive_power

  !> Gap of row k in state s, exact to its own size: x_b - x_a is formed without rounding
  !> (two-sum), so a limit it is close to is subtracted exactly.
  pure real(wp) function row_gap(scene, k, s) result(g)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(state_type), intent(in) :: s
    real(wp) :: p, q, total, rounded, low, w, w_lo
    p = 0.0_wp
    q = 0.0_wp
    low = 0.0_wp
    associate (a => scene%row_body(1, k), b => scene%row_body(2, k), n => scene%row_normal(:, k))
      if (a > 0) then
        p = n(1) * s%x(a)
        low = n(1) * s%x_lo(a)
      end if
      q = n(2) * s%x(b)
      low = low + n(2) * s%x_lo(b)
    end associate
    if (scene%gap_terms) then
      ! (a gear ratio's n x_a is rounded: its exact error joins the low part)
      if (scene%geared .and. scene%row_body(1, k) > 0) low = low + product_error(scene%row_normal(1, k), &
        s%x(scene%row_body(1, k)))
      ! (the ground's place to the clock's low part, as snap_closed puts a body on it)
      if (scene%row_drive(k) > 0) then
        call scene%drives%position_parts(scene%row_drive(k), s%t, s%t_lo, w, w_lo)
        p = -scene%row_normal(2, k) * w
        low = low - scene%row_normal(2, k) * w_lo
      end if
    end if
    total = p + q
    rounded = total - p
    g = (total + scene%row_offset(k)) + (((p - (total - rounded)) + (q - rounded)) + low)
  end function row_gap

  !> Rate of change of row k's gap at velocities v (at time t: with its moving ground end's
  !> velocity; without t, of the bodies' part alone).
  pure real(wp) function row_velocity(scene, k, v, t) result(u)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    real(wp), intent(in) :: v(:)
    real(wp), intent(in), optional :: t
    u = scene%row_normal(2, k) * v(scene%row_body(2, k))
    if (scene%row_body(1, k) > 0) then
      u = u + scene%row_normal(1, k) * v(scene%row_body(1, k))
    else if (present(t)) then
      if (scene%drives%n > 0) u = u + ground_motion(scene, k, t, 1)
    end if
  end function row_velocity

  !> n_k . y with |n| (row k's ends' sum of |y|; a geared row's a end counts once, not n
  !> times: what it rounds is the low parts, far below the step's term).
  pure real(wp) function row_abs(scene, k, y)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    real(wp), intent(in) :: y(:)
    row_abs = abs(y(scene%row_body(2, k)))
    if (scene%row_body(1, k) > 0) row_abs = row_abs + abs(y(scene%row_body(1, k)))
  end function row_abs

  !> Rounding level of row k's gap in state s after the gap moved by `moved` (as the
  !> two-body engine's gap_tolerance: the low parts, what a step moved it, and a gap
  !> closing within the clock's resolution).
  pure real(wp) function row_gap_tolerance(scene, k, s, moved) result(tol)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(state_type), intent(in) :: s
    real(wp), intent(in) :: moved
    tol = gap_rounding * (moved + row_abs(scene, k, s%x_lo)) + &
      time_rounding * max(abs(s%t), scene%dt) * max(0.0_wp, -row_velocity(scene, k, s%v, s%t))
    ! A moving ground's w(t) is rounded where it is evaluated (its sine: row_gap's
    ! position_parts forms v t exactly).
    if (scene%drives%n > 0) then
      if (scene%row_drive(k) > 0) tol = tol + gap_rounding * scene%drives%rounded_part(scene%row_drive(k), s%t)
    end if
  end function row_gap_tolerance

  !> Hermite coefficients of each body's displacement over the step from a to b.
  pure subroutine dense_output(a, b, step, c)
    type(state_type), intent(in) :: a, b
    real(wp), intent(in) :: step
    real(wp), intent(out) :: c(:, :)
    integer :: i
    do i = 1, size(a%x)
      c(:, i) = hermite((b%x(i) - a%x(i)) + (b%x_lo(i) - a%x_lo(i)), a%v(i), b%v(i), step)
    end do
  end subroutine dense_output

  !> Earliest event in (0, step] of the step from a to b: a gap of a row not held closing, a
  !> body sliding with friction stopping, or (forces that vary) the mode failing; found and
  !> index say what and where (found_none: theta past the step). The mode's accelerations
  !> at a (the tolerances' acc0, acc_rounding) are formed when a test first needs them
  !> (start_forces): most steps of a few bodies have every row clear of its gap and no
  !> body sliding, and need none.
  subroutine locate_nbody(scene, mode, work, polynomial, a, b, step, kept, theta, found, index)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(mode_work_type), intent(inout) :: work
    logical, intent(in) :: polynomial     !< the motion is a cubic: the dense output is exact
    type(state_type), intent(in) :: a, b
    type(kept_forces_type), intent(in) :: kept      !< the step's (its external forces at a)
    real(wp), intent(in) :: step
    real(wp), intent(out) :: theta
    integer, intent(out) :: found, index
    real(wp) :: c(3, scene%n_bodies), p(0:3), q(0:3), candidate, acc0(scene%n_bodies), f(scene%n_bodies), &
      acc_rounding
    integer :: k, i
    logical :: started
    theta = huge(1.0_wp)
    found = found_none
    index = 0
    started = .false.
    call dense_output(a, b, step, c)
    do k = 1, scene%n_rows
      if (mode%active(k)) cycle
      call gap_cubic(scene, k, a, c, step, p, q)
      if (p(0) - step * (abs(p(1)) + step * (abs(p(2)) + step * abs(p(3)))) > 0.0_wp) cycle
      ! Nor can a row not inside its gap whose ends do not move against each other over the
      ! step (between bodies at rest, a standing train's buffers): earliest_crossing finds
      ! no crossing of a constant p(0) >= 0 whatever the tolerances (all >= 0), and a
      ! result past the step is dropped (advance), so skipping it changes nothing.
      if (p(0) >= 0.0_wp .and. all(p(1:3) == 0.0_wp)) cycle
      call start_forces()
      q(0) = row_gap_tolerance(scene, k, a, 0.0_wp)
      q(2) = q(2) + acc_rounding
      ! A motion that is not a cubic is only approximated by it: the dips the cubic's wrong
      ! curvature makes at a gap just released do not count (the step's end is checked on
      ! the integrator's own state: gaps_hold).
      if (.not. polynomial) q(2) = q(2) + abs(p(2) - 0.5_wp * (row_velocity(scene, k, acc0) + &
        ground_motion(scene, k, a%t, 2)))
      candidate = earliest_crossing(p, step, q)
      if (candidate < theta) then
        theta = candidate
        found = found_row
        index = k
      end if
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
      ! (a body held still, against a wall, that slides on a belt of sine speed: its slip
      ! -V(t) stops where the belt does, on the cubic below, the body's part 0)
      if (mode%group(i) == 0 .and. .not. still_on_sine_belt(scene, mode, i)) then
        ! A body held to a moving ground that slides: its velocity is w'(t), whose zero may
        ! fall between two doubles of the clock; past it within the clock's rounding
        ! (gaps_hold) it stops at once, for the event point to take the new direction.
        if (scene%drives%n == 0) cycle
        if (mode%drive(i) == 0) cycle
        if (mode%sgn(i) * slip(scene, i, a%v(i), a%t) < 0.0_wp .and. &
          abs(slip(scene, i, a%v(i), a%t)) <= clock_band(scene, mode%drive(i), a%t)) then
          theta = 0.0_wp
          found = found_body
          index = i
          return
        end if
        cycle
      end if
      ! (the slip: velocity relative to the body's friction surface)
      p = mode%sgn(i) * [slip(scene, i, c(1, i), a%t), 2.0_wp * c(2, i), 3.0_wp * c(3, i), 0.0_wp]
      q = [velocity_rounding * max(abs(a%v(i)), abs(b%v(i)), abs(b%v(i) - a%v(i))), 0.0_wp, 0.0_wp, 0.0_wp]
      if (.not. polynomial) then
        call start_forces()
        q(1) = q(1) + abs(p(1) - mode%sgn(i) * acc0(i))
      end if
      if (scene%belt_moves) call belt_less(scene, i, mode%sgn(i), a%t, step, p, q)
      ! (held still, its velocity is 0 and its slip -V: within V's rounding of its zero, the
      ! stop the event point took)
      if (mode%group(i) == 0) q(0) = q(0) + velocity_rounding * (abs(scene%body_belt(i)) + abs(scene%body_belt_amp(i)))
      candidate = earliest_crossing(p, step, q)
      if (candidate < theta) then
        theta = candidate
        found = found_body
        index = i
      end if
    end do
    if (scene%n_stops > 0 .or. scene%n_frictions > 0) call start_forces()
    if (scene%n_stops > 0) call locate_stops(scene, mode, a, c, step, acc0, acc_rounding, theta, found, index)
    if (scene%n_frictions > 0) call relative_stops(scene, mode, a, b, step, c, polynomial, acc0, theta, found, index)
    if (mode%held .and. (scene%forcing%varies .or. scene%springs%present .or. .not. scene%drives%polynomial &
        .or. scene%stribeck .or. scene%belt_moves)) &
      call mode_crossing(scene, mode, work, a, c, min(theta, step), theta, found)

  contains

    !> The applied forces f and the mode's accelerations acc0 at a, and their rounding
    !> acc_rounding (once a location).
    subroutine start_forces()
      if (started) return
      started = .true.
      if (kept%holds(a%t)) then
        call nbody_force(scene, a%t, a%x, a%x_lo, a%v, f, mode%engaged, kept%f(:, kept%now))
      else
        call nbody_force(scene, a%t, a%x, a%x_lo, a%v, f, mode%engaged)
      end if
      if (scene%stribeck) call add_stribeck_forces(scene, mode%sgn, a%v, a%t, f)
      call mode_acceleration(scene, mode, a%t, f, acc0)
      acc_rounding = 1.0e3_wp * eps_wp * sum(abs(f)) / minval(scene%body_mass)
    end subroutine start_forces
  end subroutine locate_nbody

  !> Whether body i, held still (group 0) and sliding, is on a belt of sine speed and on no
  !> moving ground (locate_nbody: its slip's stop is the belt's).
  pure logical function still_on_sine_belt(scene, mode, i)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    integer, intent(in) :: i
    still_on_sine_belt = .false.
    if (.not. scene%belt_moves) return
    still_on_sine_belt = belt_moving(scene, i) .and. mode%drive(i) == 0
  end function still_on_sine_belt

  !> The slip cubic p of body i (sliding direction sgn) over the step from t less its
  !> accelerating belt's: the belt's speed on its own Hermite cubic (V and V' at the step's
  !> ends), whose root refine_nbody polishes on the exact V (as a moving ground's gap); the
  !> belt's slope's rounding beside the tolerance q(1) of p's.
  pure subroutine less_belt(scene, i, sgn, t, step, p, q)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: i
    real(wp), intent(in) :: sgn, t, step
    real(wp), intent(inout) :: p(0:3), q(0:3)
    real(wp) :: belt(3)
    if (.not. belt_moving(scene, i)) return
    belt = hermite(belt_speed(scene, i, t + step) - belt_speed(scene, i, t), belt_rate(scene, i, t, 2), &
      belt_rate(scene, i, t + step, 2), step)
    p(1:3) = p(1:3) - sgn * belt
    q(1) = q(1) + abs(belt(1)) * velocity_rounding
  end subroutine less_belt

  !> What the rounding of the clock at t moves drive d's velocity w' by.
  pure real(wp) function clock_band(scene, d, t) result(band)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: d
    real(wp), intent(in) :: t
    band = time_rounding * max(abs(t), scene%dt) * abs(scene%drives%acceleration(d, t))
  end function clock_band

  !> Row k's gap over the step from a with dense output c, as a cubic p in theta, and the
  !> rounding of its terms of order 1 to 3 (q(1:3); q(0) is left to the caller).
  subroutine gap_cubic(scene, k, a, c, step, p, q)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: k
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: c(:, :), step
    real(wp), intent(out) :: p(0:3), q(0:3)
    q(0) = 0.0_wp
    associate (ea => scene%row_body(1, k), eb => scene%row_body(2, k), n => scene%row_normal(:, k))
      p(0) = row_gap(scene, k, a)
      p(1:3) = n(2) * c(:, eb)
      q(1:3) = gap_rounding * abs(c(:, eb))
      if (ea > 0) then
        p(1:3) = p(1:3) + n(1) * c(:, ea)
        q(1:3) = q(1:3) + gap_rounding * abs(n(1) * c(:, ea))
      else if (scene%drives%n > 0) then
        ! A moving ground end on its own cubic over the step (exact for ground_v; the
        ! step's end is checked on the exact w: gaps_hold).
        if (scene%row_drive(k) > 0) p(1:3) = p(1:3) + hermite(-n(2) * scene%drives%displacement( &
          scene%row_drive(k), a%t, step), ground_motion(scene, k, a%t, 1), ground_motion(scene, k, &
          scene%drives%before_corner(a%t, a%t + step), 1), step)
      end if
    end associate
  end subroutine gap_cubic

  !> The compliant stops' events on the step's dense output c from a (docs/method.md section
  !> 10; as the deleted two-body engine's impact1d_location did), if earlier than theta:
  !> an open stop's gap closing (its engagement: found_row), an engaged stop's force F =
  !> -(k gap + c gap') falling through zero (its release: found_stop), and a stop released
  !> inside (gap < 0) whose F rises through zero (engaged again: found_stop). On the cubic
  !> gap(theta) F is a cubic too; its tolerance is the gap's carried through the same
  !> combination. acc0, acc_rounding: the mode's accelerations at a and their rounding.
  subroutine locate_stops(scene, mode, a, c, step, acc0, acc_rounding, theta, found, index)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: c(:, :), step, acc0(:), acc_rounding
    real(wp), intent(inout) :: theta
    integer, intent(inout) :: found, index
    real(wp) :: g(0:3), q(0:3), force(0:3), tol(0:3), band, candidate
    integer :: j, r, kind
    do j = 1, scene%n_stops
      r = scene%n_rows + j
      call gap_cubic(scene, r, a, c, step, g, q)
      q(0) = row_gap_tolerance(scene, r, a, 0.0_wp)
      q(2) = q(2) + acc_rounding + abs(g(2) - 0.5_wp * (row_velocity(scene, r, acc0) + ground_motion(scene, r, a%t, 2)))
      band = stop_gap_band(scene, r, a)
      if (.not. mode%engaged(j) .and. g(0) >= -band) then
        ! Open (released at the limit, within its rounding, it is open): the gap closing.
        candidate = earliest_crossing(g, step, [max(q(0), band), q(1:3)])
        kind = found_row
      else
        call stop_force_cubic(scene%row_k(r), scene%row_c(r), g, q, force, tol)
        tol(0) = max(tol(0), stop_force_band(scene, r, a))
        ! Engaged: F >= 0 until it falls through zero. Released inside: F < 0 until it rises.
        if (.not. mode%engaged(j)) force = -force
        candidate = earliest_crossing(force, step, tol)
        kind = found_stop
      end if
      if (candidate < theta) then
        theta = candidate
        found = kind
        index = r
      end if
    end do
  end subroutine locate_stops

  !> Within how much of its limit a compliant stop row r is at it in state s: the gap's
  !> rounding and what the rounding of the clock at an event moves it by, either way (a
  !> stop released at its limit leaves it, 1e-17 m inside, at once: open, not engaged again).
  pure real(wp) function stop_gap_band(scene, r, s) result(band)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: r
    type(state_type), intent(in) :: s
    band = row_gap_tolerance(scene, r, s, 0.0_wp) + &
      time_rounding * max(abs(s%t), scene%dt) * abs(row_velocity(scene, r, s%v, s%t))
  end function stop_gap_band

  !> The rounding of stop row r's force -(k gap + c gap') in state s: what counts as zero at
  !> its engagement and release.
  pure real(wp) function stop_force_band(scene, r, s) result(band)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: r
    type(state_type), intent(in) :: s
    band = 1.0e3_wp * eps_wp * (scene%row_k(r) * max(abs(row_gap(scene, r, s)), stop_gap_band(scene, r, s)) + &
      scene%row_c(r) * abs(row_velocity(scene, r, s%v, s%t))) + tiny(1.0_wp)
  end function stop_force_band

  !> The earliest relative stop of a friction contact between bodies that slides (its
  !> relative velocity on the dense output c reaching 0), located as a body's stop is;
  !> theta, found (found_friction) and index (the contact) updated when earlier.
  subroutine relative_stops(scene, mode, a, b, step, c, polynomial, acc0, theta, found, index)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: a, b
    real(wp), intent(in) :: step, c(:, :), acc0(:)
    logical, intent(in) :: polynomial
    real(wp), intent(inout) :: theta
    integer, intent(inout) :: found, index
    real(wp) :: p(0:3), q(0:3), candidate, u0, u1
    integer :: j
    do j = 1, scene%n_frictions
      if (mode%friction_sgn(j) == 0.0_wp) cycle
      associate (ea => scene%friction_body(1, j), eb => scene%friction_body(2, j), sgn => mode%friction_sgn(j))
        p = sgn * [c(1, eb) - c(1, ea), 2.0_wp * (c(2, eb) - c(2, ea)), 3.0_wp * (c(3, eb) - c(3, ea)), 0.0_wp]
        u0 = relative_velocity(scene, j, a%v)
        u1 = relative_velocity(scene, j, b%v)
        q = [velocity_rounding * max(abs(a%v(ea)) + abs(a%v(eb)), abs(b%v(ea)) + abs(b%v(eb)), abs(u1 - u0)), &
          0.0_wp, 0.0_wp, 0.0_wp]
        if (.not. polynomial) q(1) = q(1) + abs(p(1) - sgn * relative_velocity(scene, j, acc0))
      end associate
      candidate = earliest_crossing(p, step, q)
      if (candidate < theta) then
        theta = candidate
        found = found_friction
        index = j
      end if
    end do
  end subroutine relative_stops

  !> v with the ends of each stuck friction contact at one velocity (a's), as the mode moves
  !> them: the dense output's rounding is no relative slip.
  pure subroutine hold_pairs(scene, mode, v)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    real(wp), intent(inout) :: v(:)
    integer :: j
    do j = 1, scene%n_frictions
      if (mode%friction_stuck(j)) v(scene%friction_body(2, j)) = v(scene%friction_body(1, j))
    end do
  end subroutine hold_pairs

  !> The first instant in (0, until] at which the mode no longer holds (the mode solved anew
  !> with its held rows as the candidates differs), by bisection on the dense output c of
  !> the step from a: theta and found updated when there is one.
  subroutine mode_crossing(scene, mode, work, a, c, until, theta, found)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(mode_work_type), intent(inout) :: work
    type(state_type), intent(in) :: a
    real(wp), intent(in) :: c(:, :), until
    real(wp), intent(inout) :: theta
    integer, intent(inout) :: found
    real(wp) :: lo, hi, mid
    if (holds_at(until)) return
    lo = 0.0_wp
    hi = until
    do while (hi - lo > 2.0_wp * eps_wp * max(abs(a%t + hi), until))
      mid = 0.5_wp * (lo + hi)
      if (holds_at(mid)) then
        lo = mid
      else
        hi = mid
      end if
    end do
    ! A located stop (a body's or a friction contact's, at theta = until) turns its sliding
    ! direction on the dense output there, so the mode solved at it differs: a failure no
    ! earlier than the bisection can tell is that stop, which refine_nbody polishes on the
    ! integrator's state (as found_hold it stayed at the cubic's root: 2e-4 s off at dt = 0.1).
    if ((found == found_body .or. found == found_friction) .and. until == theta .and. &
      until - hi <= 2.0_wp * eps_wp * max(abs(a%t + hi), until)) return
    theta = hi
    found = found_hold

  contains

    !> Whether the mode is the one solved theta into the step.
    logical function holds_at(tau)
      real(wp), intent(in) :: tau
      type(body_mode_type) :: probe
      real(wp), dimension(scene%n_bodies) :: f, df, dx, v, sliding
      integer :: status
      dx = a%x_lo + tau * (c(1, :) + tau * (c(2, :) + tau * c(3, :)))
      v = c(1, :) + tau * (2.0_wp * c(2, :) + 3.0_wp * tau * c(3, :))
      ! A body held still stays exactly still (on its belt); one that slides keeps its direction.
      where (mode%stuck) v = 0.0_wp
      if (scene%belts) then
        where (mode%stuck) v = scene%body_belt
        if (scene%belt_moves) call stuck_on_belts(tau, v)
      end if
      if (scene%n_frictions > 0) call hold_pairs(scene, mode, v)
      call nbody_force(scene, a%t + tau, a%x, dx, v, f, mode%engaged)
      call nbody_rate(scene, a%t + tau, v, df, mode%engaged)
      if (scene%drives%n > 0) call shift_to_drives(scene, a%t + tau, mode%active, f, df)
      if (scene%belt_moves) call shift_to_belts(scene, a%t + tau, v, f, df)
      probe = mode
      call solve_body_mode(scene, work, f, df, v, a%t + tau, mode%active, probe, status)
      holds_at = status == mode_solved
      if (holds_at .and. scene%stribeck) then
        ! begun weighs the probe's loads: on the bodies that slide in both modes they hold
        ! Stribeck's part of sliding friction, beyond f_slide's -F sgn (without it a group
        ! pushed by c(u) > F did not break a friction contact away at its bound)
        sliding = merge(probe%sgn, 0.0_wp, .not. mode%stuck)
        call add_stribeck_forces(scene, sliding, v, a%t + tau, f)
      end if
      if (holds_at) holds_at = same_mode(probe, mode) .or. .not. begun(probe, f)
    end function holds_at

    !> v of the stuck bodies on accelerating belts: their belt's speed at a%t + tau.
    subroutine stuck_on_belts(tau, v)
      real(wp), intent(in) :: tau
      real(wp), intent(inout) :: v(:)
      integer :: i
      do i = 1, scene%n_bodies
        if (mode%stuck(i) .and. belt_moving(scene, i)) v(i) = belt_speed(scene, i, a%t + tau)
      end do
    end subroutine stuck_on_belts

    !> Whether the probe's motion has begun. The mode solve calls a force within rounding of
    !> its bound a tie and decides it by the rate, some 1e-12 s before the force reaches the
    !> bound; the mode fails where it reaches it, as the two-body engine's hold conditions
    !> turn negative: a body that breaks away, with its group in the probe (the bodies that
    !> break away with it at their static bounds, the others at their sliding ones), has
    !> force beyond those bounds the way it slides; a held row that the probe lets go does
    !> not move back into its gap. Any other change counts at once.
    logical function begun(probe, f)
      type(body_mode_type), intent(in) :: probe
      real(wp), intent(in) :: f(:)
      real(wp) :: acc(scene%n_bodies), way(scene%n_bodies), lead(0:scene%n_bodies), s(scene%n_bodies)
      logical :: against
      integer :: i, k
      ! (a geared group's load is sum s_i f_i, body i moving s_i times its coordinate:
      ! docs/method.md section 14)
      s = 1.0_wp
      if (scene%geared) then
        call probe%geared_response(f + probe%f_slide, acc)
        s = probe%scale
      else
        call probe%acceleration(f, acc)
      end if
      begun = any(probe%active .and. .not. mode%active) .or. any(probe%stuck .and. .not. mode%stuck)
      lead = 0.0_wp
      do i = 1, scene%n_bodies
        way(i) = probe%sgn(i)
        if (way(i) == 0.0_wp) way(i) = sign(1.0_wp, acc(i))
        if (mode%stuck(i) .and. .not. probe%stuck(i)) then
          lead(probe%group(i)) = lead(probe%group(i)) + s(i) * (f(i) - scene%body_static(i) * way(i))
        else
          lead(probe%group(i)) = lead(probe%group(i)) + s(i) * (f(i) + probe%f_slide(i))
          if (mode%sgn(i) /= probe%sgn(i)) begun = .true.
        end if
      end do
      against = .false.
      do i = 1, scene%n_bodies
        if (mode%stuck(i) .and. .not. probe%stuck(i) .and. probe%group(i) > 0) &
          against = against .or. way(i) * s(i) * lead(probe%group(i)) < 0.0_wp
      end do
      do k = 1, scene%n_rows
        if (mode%active(k) .and. .not. probe%active(k)) against = against .or. row_velocity(scene, k, acc) < 0.0_wp
      end do
      if (scene%n_frictions > 0) call pairs_against(probe, lead, against)
      begun = begun .or. .not. against
    end function begun

    !> begun's test for the friction contacts that break away (stuck in the mode, not in the
    !> probe): each, at its static bound the way the probe slides it, must have its ends'
    !> groups accelerate apart that way (lead: the probe's group loads, at sliding bounds).
    subroutine pairs_against(probe, lead, against)
      type(body_mode_type), intent(in) :: probe
      real(wp), intent(inout) :: lead(0:)
      logical, intent(inout) :: against
      integer :: k
      real(wp) :: rel
      do k = 1, scene%n_frictions
        if (.not. mode%friction_stuck(k) .or. probe%friction_stuck(k) .or. probe%friction_sgn(k) == 0.0_wp) cycle
        associate (ga => probe%group(scene%friction_body(1, k)), gb => probe%group(scene%friction_body(2, k)), &
            extra => (scene%friction_static(k) - scene%friction_slide(k)) * probe%friction_sgn(k))
          lead(gb) = lead(gb) - extra
          lead(ga) = lead(ga) + extra
          rel = 0.0_wp
          if (gb > 0) rel = lead(gb) / probe%group_mass(gb)
          if (ga > 0) rel = rel - lead(ga) / probe%group_mass(ga)
          against = against .or. probe%friction_sgn(k) * rel < 0.0_wp
        end associate
      end do
    end subroutine pairs_against
  end subroutine mode_crossing

  !> Re-take the step to the located time and polish it by Newton's method on the watched
  !> function on the integrator's own state (exact under polynomial forcing at once). A row
  !> with a moving ground end was located on its cubic, whose root may come before the
  !> exact one, and so was a sliding body's stop under forcing that is not polynomial (the
  !> cubic's velocity), and a friction contact's relative stop (found_friction) likewise:
  !> Newton may then go on up to the step taken (limit).
  subroutine refine_nbody(scene, mode, polynomial, a, step, found, index, b, kept, limit)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    logical, intent(in) :: polynomial     !< the motion is a cubic: the dense output is exact
    type(state_type), intent(in) :: a
    real(wp), intent(inout) :: step
    integer, intent(in) :: found, index
    type(state_type), intent(inout) :: b
    type(kept_forces_type), intent(inout) :: kept     !< nbody_step's
    real(wp), intent(in), optional :: limit
    real(wp) :: value, slope, tol, located_step, f(scene%n_bodies), acc(scene%n_bodies)
    integer :: iteration
    located_step = step
    if (present(limit) .and. found == found_row .and. scene%drives%n > 0) then
      if (scene%row_drive(index) > 0) located_step = limit
    end if
    if (present(limit) .and. (found == found_body .or. found == found_friction) .and. .not. polynomial) &
      located_step = limit
    call nbody_step(scene, mode, a, step, b, kept)
    if (all(found /= [found_row, found_body, found_stop, found_friction])) return
    do iteration = 1, 8
      if (found == found_body .or. found == found_friction) then
        call nbody_force(scene, b%t, b%x, b%x_lo, b%v, f, mode%engaged)
        call law_acceleration(scene, mode, b%t, b%v, f, acc)
        if (found == found_body) then
          value = slip(scene, index, b%v(index), b%t)
          slope = acc(index) - belt_rate(scene, index, b%t, 2)
          tol = velocity_rounding * max(abs(a%v(index)), abs(value))
        else
          ! a contact's stop: its ends' relative velocity v_b - v_a, rounded as relative_stops
          associate (ea => scene%friction_body(1, index), eb => scene%friction_body(2, index))
            value = relative_velocity(scene, index, b%v)
            slope = relative_velocity(scene, index, acc)
            tol = velocity_rounding * max(abs(a%v(ea)) + abs(a%v(eb)), abs(value))
          end associate
        end if
      else if (found == found_stop) then
        ! A stop's force F = -(k gap + c gap'), its rate -(k gap' + c gap'').
        call nbody_force(scene, b%t, b%x, b%x_lo, b%v, f, mode%engaged)
        call mode_acceleration(scene, mode, b%t, f, acc)
        slope = row_velocity(scene, index, b%v, b%t)
        value = -(scene%row_k(index) * row_gap(scene, index, b) + scene%row_c(index) * slope)
        tol = stop_force_band(scene, index, b)
        slope = -(scene%row_k(index) * slope + scene%row_c(index) * (row_velocity(scene, index, acc) + &
          ground_motion(scene, index, b%t, 2)))
      else
        value = row_gap(scene, index, b)
        slope = row_velocity(scene, index, b%v, b%t)
        tol = row_gap_tolerance(scene, index, b, row_abs(scene, index, (b%x - a%x) + (b%x_lo - a%x_lo)))
      end if
      if (abs(value) <= tol .or. slope == 0.0_wp) exit
      if (step - value / slope <= 0.0_wp .or. step - value / slope > located_step) exit
      step = step - value / slope
      call nbody_step(scene, mode, a, step, b, kept)
    end do
  end subroutine refine_nbody

  !> No step from s may end at b with a gap below zero beyond rounding (a root the location
  !> missed: only under forcing that is not polynomial), nor a sliding body past zero; the
  !> located row (else 0) is put on its constraint at the event point.
  pure logical function gaps_hold(scene, mode, s, b, located)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: s, b
    integer, intent(in) :: located
    integer :: k, i
    gaps_hold = .true.
    do k = 1, scene%n_rows
      if (mode%active(k) .or. k == located) cycle
      if (row_gap(scene, k, b) < -row_gap_tolerance(scene, k, b, moved(k))) gaps_hold = .false.
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp) cycle
      if (mode%sgn(i) * slip(scene, i, b%v(i), b%t) < -velocity_rounding * max(abs(s%v(i)), abs(b%v(i)), &
          abs(b%v(i) - s%v(i))) - held_band(i)) gaps_hold = .false.
    end do
    do k = 1, scene%n_frictions
      if (mode%friction_sgn(k) == 0.0_wp) cycle
      associate (ea => scene%friction_body(1, k), eb => scene%friction_body(2, k))
        if (mode%friction_sgn(k) * relative_velocity(scene, k, b%v) < -velocity_rounding * &
          max(abs(s%v(ea)) + abs(s%v(eb)), abs(b%v(ea)) + abs(b%v(eb)))) gaps_hold = .false.
      end associate
    end do

  contains

    !> A body held to a moving ground has w'(t) formed at the clock's leading double: where
    !> w' turns between two doubles (a sine ground at its top) it passes zero with no time
    !> to locate; what the clock's rounding moves w' by is a stop (locate_nbody, theta 0).
    pure real(wp) function held_band(i)
      integer, intent(in) :: i
      held_band = 0.0_wp
      if (scene%drives%n == 0) return
      if (mode%drive(i) > 0) held_band = clock_band(scene, mode%drive(i), b%t)
    end function held_band

    !> What the step moved row k's gap by (row_abs of the bodies' displacements, formed for
    !> its two ends only: over all N bodies for each row, it was O(N) a row and most of a
    !> long chain's step).
    pure real(wp) function moved(k)
      integer, intent(in) :: k
      associate (ea => scene%row_body(1, k), eb => scene%row_body(2, k))
        moved = abs((b%x(eb) - s%x(eb)) + (b%x_lo(eb) - s%x_lo(eb)))
        if (ea > 0) moved = moved + abs((b%x(ea) - s%x(ea)) + (b%x_lo(ea) - s%x_lo(ea)))
      end associate
    end function moved
  end function gaps_hold
end module impact1d_nbody_step
