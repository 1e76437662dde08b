!> Closed-form steps of the N-body engine (docs/method.md section 9; the two-body engine's
!> glide, once): under forces that are constant between stops a mode's
!> accelerations are constant, so its motion is an exact quadratic and the first instant a
!> row's gap, a sliding body's velocity or a friction contact's relative velocity can reach
!> zero is known in closed form when the mode starts (the quiet time). The steps that end
!> before it can meet no event: they are taken without forces, mode solves or location, in
!> the very arithmetic of nbody_step's RK4 step under constant accelerations (the same bits:
!> a run gives the same samples and events with or without the glide). Under force tables
!> the forces are linear in t between corners: the motion is a cubic, the quiet time a
!> bound over the segment to the next corner (a conservative quadratic below the gaps'
!> cubic; the held mode's conditions, linear in t, checked at the segment's end), and the
!> steps before it are nbody_step's own, without their location.
module impact1d_nbody_glide
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, step_length
  use impact1d_state, only: state_type, add_compensated, finite_state, take_state, renormalise
  use impact1d_output, only: sink_type, run_stats, checkpoint
  use impact1d_yardsticks, only: gap_rounding, velocity_rounding
  use impact1d_body_mode, only: body_mode_type, mode_work_type, relative_velocity
  use impact1d_nbody_step, only: row_gap, row_velocity, row_abs, nbody_step, mode_crossing, kept_forces_type
  use impact1d_events, only: first_negative
  implicit none
  private
  public :: glide_type, new_glide, find_quiet_time, glide

  !> How far from its limit (in multiples of its rounding) a gap or a sliding velocity must
  !> stay for the location to find nothing there, whatever the steps' rounding did to the
  !> exact quadratic (a few eps of the distance travelled); the quiet time is then taken 1%
  !> short of that, as the two-body engine's find_quiet_times did.
  real(wp), parameter :: band_factor = 1.0e3_wp, quiet_fraction = 0.99_wp

  !> What the glide needs of the scene (once a run) and of the current mode (at each event
  !> point: find_quiet_time).
  type :: glide_type
    !> The scene's forces are constant or force tables and nothing else acts (no sines,
    !> springs or compliant stops, no moving ground, no friction law): the engine may glide.
    logical :: able = .false.
    !> Some force is a table: the forces vary, the glided steps are nbody_step's.
    logical :: table = .false.
    !> Steps ending before this time meet no event (-huge: none may glide).
    real(wp) :: t_quiet = -huge(1.0_wp)
    !> Some body slides with friction (the step books friction's loss).
    logical :: sliding = .false.
    real(wp), allocatable :: force(:)   !< (N) the applied forces (at the event point: tables)
    real(wp), allocatable :: acc(:)     !< (N) the mode's accelerations under them
    real(wp), allocatable :: rate(:)    !< (N) the forces' rate until the next corner (tables)
    real(wp), allocatable :: jerk(:)    !< (N) the accelerations' rate under it (0: constant forces)
    !> The state is closed_step's fixed point (find_quiet_time's fixed_point): a step moves the
    !> clock alone, until the state changes otherwise (an event point; a located step:
    !> run_nbody sets it false).
    logical :: fixed = .false.
  end type glide_type

contains

  !> The glide's memory (once a run) and whether the scene allows it.
  subroutine new_glide(scene, g)
    type(scene_type), intent(in) :: scene
    type(glide_type), intent(inout) :: g
    g%able = .not. (.not. scene%forcing%is_polynomial() .or. scene%springs%present .or. scene%n_stops > 0 .or. &
      scene%drives%n > 0 .or. scene%belts .or. scene%stribeck .or. scene%stage_powers)
    g%table = scene%forcing%varies
    g%t_quiet = -huge(1.0_wp)
    if (.not. g%able) return
    allocate(g%force(scene%n_bodies), g%acc(scene%n_bodies), g%rate(scene%n_bodies), g%jerk(scene%n_bodies))
    call scene%forcing%force_all(0.0_wp, g%force)
    g%rate = 0.0_wp
    g%jerk = 0.0_wp
  end subroutine new_glide

  !> At an event point (the mode and the state s new): the mode's accelerations and the time
  !> before which none of its watched functions (nbody_step's locate_nbody: the gaps of the
  !> rows not held, the velocities of the bodies sliding with friction, the relative
  !> velocities of the friction contacts sliding; under tables the held mode too) can come
  !> near zero. Under tables the bounds hold up to the next corner (t_corner), which is a
  !> stop and an event point. O(N + rows), and under tables one mode solve at the corner.
  subroutine find_quiet_time(scene, mode, work, s, g)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(mode_work_type), intent(inout) :: work
    type(state_type), intent(in) :: s
    type(glide_type), intent(inout) :: g
    real(wp) :: tau, speed, t_corner, span
    integer :: k, i
    if (.not. g%able) return
    t_corner = huge(1.0_wp)
    span = huge(1.0_wp)
    if (g%table) call segment(scene, mode, s, g, t_corner, span)
    call mode%acceleration(g%force, g%acc)
    g%sliding = any(mode%f_slide /= 0.0_wp)
    g%fixed = .not. g%table .and. fixed_point(scene, g, s)
    tau = huge(1.0_wp)
    do k = 1, scene%n_rows
      if (mode%active(k)) cycle
      if (at_rest(scene%row_body(1, k)) .and. at_rest(scene%row_body(2, k)) .and. row_gap(scene, k, s) >= 0.0_wp) &
        cycle     ! (ends that do not move: the location skips the row too)
      ! (the cubic's term jerk tau^3 / 6 >= -|jerk| span tau^2 / 6 for tau <= span)
      tau = min(tau, clear_time(row_gap(scene, k, s), row_velocity(scene, k, s%v), row_velocity(scene, k, g%acc) - &
        abs(row_velocity(scene, k, g%jerk)) * span / 3.0_wp, &
        band_factor * gap_rounding * (row_abs(scene, k, s%x) + abs(scene%row_offset(k)))))
    end do
    do i = 1, scene%n_bodies
      if (scene%body_static(i) == 0.0_wp .or. mode%sgn(i) == 0.0_wp .or. mode%group(i) == 0) cycle
      tau = min(tau, clear_time(mode%sgn(i) * s%v(i), mode%sgn(i) * g%acc(i), mode%sgn(i) * g%jerk(i), &
        band_factor * velocity_rounding * abs(s%v(i))))
    end do
    do k = 1, scene%n_frictions
      if (mode%friction_sgn(k) == 0.0_wp) cycle
      associate (sgn => mode%friction_sgn(k))
        speed = abs(s%v(scene%friction_body(1, k))) + abs(s%v(scene%friction_body(2, k)))
        tau = min(tau, clear_time(sgn * relative_velocity(scene, k, s%v), sgn * relative_velocity(scene, k, g%acc), &
          sgn * relative_velocity(scene, k, g%jerk), band_factor * velocity_rounding * speed))
      end associate
    end do
    if (g%table .and. mode%held .and. any(g%rate /= 0.0_wp) .and. tau > 0.0_wp) &
      call held_until(scene, mode, work, s, g, span, tau)
    g%t_quiet = -huge(1.0_wp)
    if (tau >= span) then
      ! (clear to the corner: the step that ends there may glide too)
      g%t_quiet = huge(1.0_wp)
      if (t_corner < huge(1.0_wp)) g%t_quiet = nearest(t_corner, 1.0_wp)
    else if (tau > 0.0_wp) then
      g%t_quiet = s%t + quiet_fraction * tau
    end if

  contains

    !> Body j (0: the ground) stays where it is: at rest exactly, nothing accelerating it.
    logical function at_rest(j)
      integer, intent(in) :: j
      at_rest = .true.
      if (j == 0) return
      at_rest = s%v(j) == 0.0_wp .and. s%v_lo(j) == 0.0_wp .and. g%acc(j) == 0.0_wp .and. g%jerk(j) == 0.0_wp
    end function at_rest
  end subroutine find_quiet_time

  !> Under tables: the forces at s%t, their rate up to the next corner t_corner (the right
  !> derivative: exact on the segment) and the accelerations' rate in the mode; span is
  !> t_corner - s%t (huge past the last corner, where the forces are constant).
  subroutine segment(scene, mode, s, g, t_corner, span)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(state_type), intent(in) :: s
    type(glide_type), intent(inout) :: g
    real(wp), intent(out) :: t_corner, span
    call scene%forcing%force_all(s%t, g%force)
    call scene%forcing%rate(s%t, g%rate)
    call mode%rate_response(g%rate, g%jerk)
    t_corner = scene%forcing%next_breakpoint(s%t)
    span = huge(1.0_wp)
    if (t_corner < huge(1.0_wp)) span = t_corner - s%t
  end subroutine segment

  !> A held mode under a table's ramp: its conditions (contact forces, friction within its
  !> bounds) are linear in the forces, so linear in t on the segment, and hold on all of it
  !> when they hold at both ends; else tau is cut to where they first fail (mode_crossing,
  !> the location's own test, on the segment's exact cubic motion from s).
  subroutine held_until(scene, mode, work, s, g, span, tau)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(mode_work_type), intent(inout) :: work
    type(state_type), intent(in) :: s
    type(glide_type), intent(in) :: g
    real(wp), intent(in) :: span
    real(wp), intent(inout) :: tau
    real(wp) :: c(3, scene%n_bodies), theta
    integer :: found
    c(1, :) = s%v
    c(2, :) = 0.5_wp * g%acc
    c(3, :) = g%jerk / 6.0_wp
    theta = huge(1.0_wp)
    found = 0
    call mode_crossing(scene, mode, work, s, c, min(tau, span), theta, found)
    tau = min(tau, theta)
  end subroutine held_until

  !> For how long w(tau) = w0 + w1 tau + w2 tau^2 / 2 stays above the band (huge: for ever;
  !> 0: it may not be far from zero now). w0 within the band counts as clear while w moves
  !> away from zero (a gap just opened, a body just broken away), until it comes back to the
  !> band; a w0 below zero is never clear.
  pure real(wp) function clear_time(w0, w1, w2, band) result(tau)
    real(wp), intent(in) :: w0, w1, w2, band
    real(wp) :: c0, disc
    tau = 0.0_wp
    c0 = w0 - band
    if (c0 > 0.0_wp) then
      tau = first_negative(c0, w1, w2)
    else if (w0 >= 0.0_wp .and. (w1 > 0.0_wp .or. (w1 == 0.0_wp .and. w2 > 0.0_wp))) then
      ! Leaving the band: back to it at the larger root of c0 + w1 tau + w2 tau^2 / 2.
      tau = huge(1.0_wp)
      if (w2 < 0.0_wp) then
        disc = w1**2 - 2.0_wp * w2 * c0
        tau = 0.0_wp
        if (disc >= 0.0_wp) tau = (w1 + sqrt(disc)) / (-w2)
      end if
    end if
    if (tau /= tau) tau = 0.0_wp
  end function clear_time

  !> Steps from s toward t_stop while they end before the quiet time, each nbody_step's RK4
  !> step under the mode's constant accelerations (closed_step), or under tables nbody_step
  !> itself (into trial) without its location; at_stop: they reached the stop (the clock is
  !> then set to it, as advance does). Counted in stats as steps, and as glided.
  subroutine glide(scene, mode, g, t_stop, s, trial, kept, at_stop, sink, stats, error)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(glide_type), intent(in) :: g
    real(wp), intent(in) :: t_stop
    type(state_type), intent(inout) :: s, trial
    type(kept_forces_type), intent(inout) :: kept   !< advance's: kept across the steps here too
    logical, intent(out) :: at_stop
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats
    type(error_type), allocatable, intent(inout) :: error
    real(wp) :: h, remaining
    at_stop = .false.
    do
      remaining = (t_stop - s%t) - s%t_lo
      h = step_length(scene%dt, remaining)
      if (h <= 0.0_wp .or. .not. s%t + h < g%t_quiet) exit
      if (g%table) then
        call nbody_step(scene, mode, s, h, trial, kept)
        call take_state(s, trial)
        call kept%accept()
      else if (g%fixed) then
        call add_compensated(s%t, s%t_lo, h)     ! (closed_step's clock)
      else
        call closed_step(scene, mode, g, h, s)
        call kept%forget()
      end if
      at_stop = h == remaining
      if (at_stop) then
        s%t = t_stop
        s%t_lo = 0.0_wp
      end if
      stats%steps = stats%steps + 1
      stats%glided = stats%glided + 1
      if (iand(stats%steps, 4095_int64) == 0) then
        call checkpoint(sink, stats, s%t, scene%t_end, error)
        if (allocated(error)) return
      end if
      if (at_stop) exit
    end do
    ! (checked once a glide: under constant forces a state stays finite for many steps)
    if (.not. finite_state(s%x, s%v, s%work)) call raise(error, status_simulation, 'at t = ' // &
      trim(fmt(s%t)) // ': the state is no longer finite')
  end subroutine glide

  !> Whether state s is closed_step's fixed point under g's accelerations (a step of any
  !> length changes nothing but the clock): every body at rest (v and v_lo +0) with
  !> acceleration 0, and each compensated pair closed_step adds to (positions, work,
  !> friction's loss) no -0 and renormalised (renormalise leaves it as it is). Then each
  !> increment is +0 whatever h (v0 = +0, so the stages' velocities and the powers are +0),
  !> dv a zero of acc's sign, and a two-sum of such a pair and a zero leaves it unchanged.
  !> Bodies stuck under forces within their friction bounds (the tutorial's case 1, all its
  !> run) or in a run's final rest take the clock's steps alone.
  logical function fixed_point(scene, g, s)
    type(scene_type), intent(in) :: scene
    type(glide_type), intent(in) :: g
    type(state_type), intent(in) :: s
    integer :: i
    fixed_point = .false.
    do i = 1, scene%n_bodies
      if (.not. (same_bits(s%v(i), 0.0_wp) .and. same_bits(s%v_lo(i), 0.0_wp) .and. g%acc(i) == 0.0_wp .and. &
        settled(s%x(i), s%x_lo(i)))) return
    end do
    fixed_point = settled(s%work, s%work_lo) .and. settled(s%friction_loss, s%friction_lo)
  end function fixed_point

  !> The compensated pair hi + lo has no -0 and renormalise leaves it as it is.
  elemental logical function settled(hi, lo)
    real(wp), intent(in) :: hi, lo
    real(wp) :: h, l
    h = hi
    l = lo
    call renormalise(h, l)
    settled = same_bits(h, hi) .and. same_bits(l, lo) .and. .not. (hi == 0.0_wp .and. sign(1.0_wp, hi) < 0.0_wp) &
      .and. .not. (lo == 0.0_wp .and. sign(1.0_wp, lo) < 0.0_wp)
  end function settled

  !> a and b are the same double (a zero's sign too).
  elemental logical function same_bits(a, b)
    real(wp), intent(in) :: a, b
    same_bits = a == b .and. sign(1.0_wp, a) == sign(1.0_wp, b)
  end function same_bits

  !> nbody_step's RK4 step of h when every stage's acceleration is g%acc: its stages' sums,
  !> ledger (Simpson's rule on the Hermite velocity, with the end acceleration's term
  !> acc - acc) and friction's loss, operation for operation, so the bits are the step's.
  !> One pass over the bodies, O(N), nothing allocated.
  subroutine closed_step(scene, mode, g, h, s)
    type(scene_type), intent(in) :: scene
    type(body_mode_type), intent(in) :: mode
    type(glide_type), intent(in) :: g
    real(wp), intent(in) :: h
    type(state_type), intent(inout) :: s
    real(wp) :: half, v0, v1, vm, k2, k4, power0, power_m, power1, loss
    integer :: i
    half = 0.5_wp * h
    power0 = 0.0_wp
    power_m = 0.0_wp
    power1 = 0.0_wp
    loss = 0.0_wp
    call add_compensated(s%t, s%t_lo, h)
    do i = 1, scene%n_bodies
      associate (a => g%acc(i))
        v0 = s%v(i) + s%v_lo(i)
        k2 = v0 + half * a                    ! (stages 2 and 3 alike)
        k4 = v0 + h * a
        call add_compensated(s%x(i), s%x_lo(i), (h / 6.0_wp) * (v0 + 2.0_wp * (k2 + k2) + k4))
        call add_compensated(s%v(i), s%v_lo(i), (h / 6.0_wp) * (a + 2.0_wp * (a + a) + a))
        v1 = s%v(i) + s%v_lo(i)
        vm = 0.5_wp * (v0 + v1) + 0.125_wp * h * (a - a)
        power0 = power0 + g%force(i) * v0
        power_m = power_m + g%force(i) * vm
        power1 = power1 + g%force(i) * v1
        if (g%sliding) loss = loss + (-mode%f_slide(i)) * (v0 + 4.0_wp * vm + v1)
      end associate
    end do
    call add_compensated(s%work, s%work_lo, h / 6.0_wp * (power0 + 4.0_wp * power_m + power1))
    if (g%sliding) call add_compensated(s%friction_loss, s%friction_lo, h / 6.0_wp * loss)
  end subroutine closed_step
end module impact1d_nbody_glide
