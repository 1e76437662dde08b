!> The `vissim` method (docs/method.md section 7): an imitation of the tutorial's block diagram,
!> kept so that the speed/accuracy trade against the event method can be measured on the
!> same scenes. Fixed-step RK4 with no event location; collisions are seen as sign changes
!> of a gap at step ends and applied with the velocities of the step before (the diagram's
!> one-step delay); walls are limited integrators (positions clamped); friction follows the
!> diagram's rules with a zero-velocity threshold (static friction's bound when at rest).
!> Springs and dampers add their forces to the applied ones. Its errors are O(dt) by design.
!> On the bodies in lanes (impact1d_lanes) and the pair's view of the scene (scene%pair): one
!> body is the pair with an idle second lane, which nothing moves.
module impact1d_vissim
  use, intrinsic :: iso_fortran_env, only: int64
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes, to_lanes
  use impact1d_error, only: error_type, raise, status_simulation, fmt
  use impact1d_scene, only: scene_type, sample_time
  use impact1d_modes, only: pair_rows
  use impact1d_impacts, only: impulse, kinetic_energy
  use impact1d_output, only: sink_type, run_stats, emit_sample, class_impact, checkpoint
  use impact1d_event_log, only: log_event
  use impact1d_loads, only: applied_force
  implicit none
  private
  public :: run_vissim

contains

  subroutine run_vissim(scene, sink, stats, error)
    type(scene_type), intent(in) :: scene
    class(sink_type), intent(inout) :: sink
    type(run_stats), intent(inout) :: stats   !< fresh from run (its interrupt epoch set)
    type(error_type), allocatable, intent(out) :: error
    real(wp), dimension(max_lanes) :: x, v, v_prev, x_new, v_new, v_hit
    real(wp) :: t, work, friction_loss, impact_loss
    real(wp) :: ke0, pe0, h, t_sample, gap_before(pair_rows), dwork, dfriction
    real(wp) :: damping_loss, ddamping
    integer :: j_sample, k, n_order, order(pair_rows)

    ! Collisions are taken rows between the bodies first, then ground rows on what they left.
    n_order = 0
    do k = 1, scene%n_rows
      if (scene%row_body(1, k) == 0) cycle
      n_order = n_order + 1
      order(n_order) = k
    end do
    do k = 1, scene%n_rows
      if (scene%row_body(1, k) /= 0) cycle
      n_order = n_order + 1
      order(n_order) = k
    end do

    ! v is the velocity integrator's state; the diagram passes it through the zero-velocity
    ! threshold before anything uses it (Figure 13), so what moves the bodies is threshold(v).
    t = 0.0_wp
    call to_lanes(scene%body_x0, x)
    call to_lanes(scene%body_v0, v)
    work = 0.0_wp
    friction_loss = 0.0_wp
    impact_loss = 0.0_wp
    damping_loss = 0.0_wp
    ke0 = kinetic_energy(scene, threshold(v))
    pe0 = scene%springs%potential(x, [0.0_wp, 0.0_wp])
    j_sample = 0
    call emit()
    if (allocated(error)) return
    do while (j_sample < scene%n_samples)
      t_sample = sample_time(scene, j_sample)
      h = min(scene%dt, t_sample - t)
      if (t_sample - t - h <= 1.0e-9_wp * scene%dt) h = t_sample - t
      v_prev = v
      do k = 1, scene%n_rows
        gap_before(k) = gap(k, x)
      end do
      call rk4(t, x, v, h, x_new, v_new, dwork, dfriction, ddamping)
      t = t + h
      if (t_sample - t <= 1.0e-9_wp * scene%dt) t = t_sample
      x = x_new
      v = v_new
      work = work + dwork
      friction_loss = friction_loss + dfriction
      damping_loss = damping_loss + ddamping
      stats%steps = stats%steps + 1
      if (iand(stats%steps, 4095_int64) == 0) then
        call checkpoint(sink, stats, t, scene%t_end, error)
        if (allocated(error)) return
      end if
      if (.not. all(abs([x, v]) <= huge(1.0_wp))) then
        call raise(error, status_simulation, 'at t = ' // trim(fmt(t)) // ': the state is no longer finite')
        return
      end if
      ! Collisions seen at the step's end: the slot's first, then the walls on what it left.
      do k = 1, n_order
        associate (c => order(k))
          if (.not. (gap_before(c) >= 0.0_wp .and. gap(c, x) < 0.0_wp)) cycle
          v_hit = threshold(v)
          ! A wall clamps the body it faces: normal . x + offset = 0.
          if (scene%row_body(1, c) == 0) x(scene%row_body(2, c)) = -scene%row_offset(c) / scene%row_normal(2, c)
          call impulse(scene, c, scene%row_restitution(c), threshold(v_prev), v_new)
          where (scene%pair%normal(:, c) == 0.0_wp) v_new = v
          impact_loss = impact_loss + kinetic_energy(scene, threshold(v)) - kinetic_energy(scene, threshold(v_new))
          v = v_new
          v_prev = v
          call log_event(scene, sink, stats, t, class_impact, c, v_hit, threshold(v))
        end associate
      end do
      if (t == t_sample) then
        call emit()
        if (allocated(error)) return
      end if
    end do
    call sink%end_progress()

  contains

    subroutine emit()
      call emit_sample(sink, stats, t, x, threshold(v), scene%pair%mass, ke0, work, friction_loss, impact_loss, &
        scene%springs%present, [scene%springs%potential(x, [0.0_wp, 0.0_wp]), pe0, damping_loss], error)
      j_sample = j_sample + 1
    end subroutine emit

    pure real(wp) function gap(k, positions)
      integer, intent(in) :: k
      real(wp), intent(in) :: positions(max_lanes)
      gap = dot_product(scene%pair%normal(:, k), positions) + scene%row_offset(k)
    end function gap

    !> The diagram's "no movement on zero velocity": |v| <= threshold reads as zero.
    pure function threshold(velocity) result(thresholded)
      real(wp), intent(in) :: velocity(max_lanes)
      real(wp) :: thresholded(max_lanes)
      thresholded = merge(0.0_wp, velocity, abs(velocity) <= scene%zero_velocity)
    end function threshold

    !> The diagram's friction block: sliding friction when moving, otherwise the smaller of
    !> the static bound and the applied force, opposing the applied force.
    pure function friction(velocity, f) result(force)
      real(wp), intent(in) :: velocity(max_lanes), f(max_lanes)
      real(wp) :: force(max_lanes)
      where (abs(velocity) > scene%zero_velocity)
        force = -scene%pair%friction * sign(1.0_wp, velocity)
      elsewhere
        force = -sign(min(scene%pair%static_friction, abs(f)), f)
      end where
    end function friction

    !> Classical RK4 on x' = thr(v), v' = (f + friction(thr(v), f)) / m, with the work, friction
    !> and damping dissipation integrated by the same stages (f: the applied forces, springs'
    !> and dampers' included; the work is the external forces' only).
    subroutine rk4(t0, x0, v0, step, x1, v1, dw, dd, dc)
      real(wp), intent(in) :: t0, x0(max_lanes), v0(max_lanes), step
      real(wp), intent(out) :: x1(max_lanes), v1(max_lanes), dw, dd, dc
      real(wp) :: kx(max_lanes, 4), kv(max_lanes, 4), kw(4), kd(4), kc(4), f(max_lanes), fr(max_lanes)
      real(wp) :: vs(max_lanes), ts, dx(max_lanes), f_ext(max_lanes)
      integer :: stage
      real(wp), parameter :: c(4) = [0.0_wp, 0.5_wp, 0.5_wp, 1.0_wp], b(4) = [1.0_wp, 2.0_wp, 2.0_wp, 1.0_wp]
      do stage = 1, 4
        ts = t0 + c(stage) * step
        vs = v0
        dx = 0.0_wp
        if (stage > 1) vs = v0 + c(stage) * step * kv(:, stage - 1)
        if (stage > 1) dx = c(stage) * step * kx(:, stage - 1)
        vs = threshold(vs)
        call applied_force(scene, ts, x0, dx, vs, f)
        fr = friction(vs, f)
        kx(:, stage) = vs
        kv(:, stage) = (f + fr) / scene%pair%mass
        call scene%forcing%force(ts, f_ext)
        kw(stage) = dot_product(f_ext, vs)
        kd(stage) = -dot_product(fr, vs)
        kc(stage) = scene%springs%damping_power(vs)
      end do
      dc = step / 6.0_wp * dot_product(kc, b)
      x1 = x0 + step / 6.0_wp * matmul(kx, b)
      v1 = v0 + step / 6.0_wp * matmul(kv, b)
      dw = step / 6.0_wp * dot_product(kw, b)
      dd = step / 6.0_wp * dot_product(kd, b)
    end subroutine rk4
  end subroutine run_vissim
end module impact1d_vissim
