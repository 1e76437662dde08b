!> Springs and dampers of an N-body scene (docs/method.md, "Springs and dampers"), read from
!> the model's element records (scene_type's element_*): element j pulls its ends a, b (0 the
!> ground, at x = 0) together with tension k ((x_b - x_a) - rest) + c (v_b - v_a). The
!> N-body engine's counterpart of impact1d_springs (the two-body kernels' lanes): here the
!> ends are looked up by index, so a chain's cost is its number of elements, not N^2.
!> An element whose ground end moves (scene%element_drive) acts on x_b - w(t) and v_b - w'(t)
!> when the time t is passed (every N-body engine call passes it when the scene has drives).
module impact1d_elements
  use impact1d_kinds, only: wp
  use impact1d_scene, only: scene_type
  implicit none
  private
  public :: add_element_forces, add_moving_element_forces, add_element_rates, element_potential, &
    element_damping_power, element_drive_power

contains

  !> y at end e of an element or row (0: the ground, where y is 0).
  pure real(wp) function at_end(y, e)
    real(wp), intent(in) :: y(:)
    integer, intent(in) :: e
    at_end = 0.0_wp
    if (e > 0) at_end = y(e)
  end function at_end

  !> Element j's ground end's position (order 0) or velocity (1) at t when it moves, else 0.
  pure real(wp) function anchor(scene, j, order, t)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j, order
    real(wp), intent(in), optional :: t
    anchor = 0.0_wp
    if (.not. present(t) .or. scene%drives%n == 0) return
    if (scene%element_drive(j) == 0) return
    if (order == 0) then
      anchor = scene%drives%position(scene%element_drive(j), t)
    else
      anchor = scene%drives%velocity(scene%element_drive(j), t)
    end if
  end function anchor

  !> Element j's elongation at positions x + dx (dx: low parts and stage displacements,
  !> added after the large terms cancel).
  pure real(wp) function elongation(scene, j, x, dx)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:)
    associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
      elongation = ((at_end(x, b) - at_end(x, a)) - scene%element_rest(j)) + (at_end(dx, b) - at_end(dx, a))
    end associate
  end function elongation

  !> elongation at time t, a moving ground end where it is then.
  pure real(wp) function moving_elongation(scene, j, x, dx, t) result(elongation)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:), t
    associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
      if (a == 0) then
        elongation = ((x(b) - anchor(scene, j, 0, t)) - scene%element_rest(j)) + dx(b)
      else
        elongation = ((x(b) - x(a)) - scene%element_rest(j)) + (dx(b) - dx(a))
      end if
    end associate
  end function moving_elongation

  !> Element j's tension at positions x + dx, velocities v, time t (optional: a still ground).
  pure real(wp) function tension_of(scene, j, x, dx, v, t) result(tension)
    type(scene_type), intent(in) :: scene
    integer, intent(in) :: j
    real(wp), intent(in) :: x(:), dx(:), v(:)
    real(wp), intent(in), optional :: t
    associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
      tension = scene%element_k(j) * moving_elongation(scene, j, x, dx, t) + &
        scene%element_c(j) * ((at_end(v, b) - at_end(v, a)) - anchor(scene, j, 1, t))
    end associate
  end function tension_of

  !> f += the elements' forces at positions x + dx and velocities v (a still ground; moving
  !> ones: add_moving_element_forces).
  pure subroutine add_element_forces(scene, x, dx, v, f)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:), v(:)
    real(wp), intent(inout) :: f(:)
    real(wp) :: tension
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        tension = scene%element_k(j) * elongation(scene, j, x, dx) + &
          scene%element_c(j) * (at_end(v, b) - at_end(v, a))
        if (a > 0) f(a) = f(a) + tension
        f(b) = f(b) - tension
      end associate
    end do
  end subroutine add_element_forces

  !> add_element_forces at time t, moving ground ends where they are then (apart, so that
  !> the loop of a scene without them stays as it was: with a branch inside it, a 50-body
  !> spring chain's element forces took half as many instructions again).
  pure subroutine add_moving_element_forces(scene, x, dx, v, f, t)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:), v(:), t
    real(wp), intent(inout) :: f(:)
    real(wp) :: tension
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        tension = tension_of(scene, j, x, dx, v, t)
        if (a > 0) f(a) = f(a) + tension
        f(b) = f(b) - tension
      end associate
    end do
  end subroutine add_moving_element_forces

  !> df += the rate of the spring forces at velocities v (at time t: relative to a moving
  !> ground end; the dampers' part needs the accelerations: left out, as impact1d_springs
  !> does).
  pure subroutine add_element_rates(scene, v, df, t)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    real(wp), intent(inout) :: df(:)
    real(wp), intent(in), optional :: t
    real(wp) :: rate
    integer :: j
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        rate = scene%element_k(j) * ((at_end(v, b) - at_end(v, a)) - anchor(scene, j, 1, t))
        if (a > 0) df(a) = df(a) + rate
        df(b) = df(b) - rate
      end associate
    end do
  end subroutine add_element_rates

  !> Potential energy stored in the springs at positions x + dx (at time t: moving ground
  !> ends where they are then).
  pure real(wp) function element_potential(scene, x, dx, t) result(pe)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:)
    real(wp), intent(in), optional :: t
    integer :: j
    pe = 0.0_wp
    if (present(t)) then
      do j = 1, scene%n_elements
        pe = pe + scene%element_k(j) * moving_elongation(scene, j, x, dx, t)**2
      end do
    else
      do j = 1, scene%n_elements
        pe = pe + scene%element_k(j) * elongation(scene, j, x, dx)**2
      end do
    end if
    pe = 0.5_wp * pe
  end function element_potential

  !> Power the dampers dissipate at velocities v (at time t: on the velocity relative to a
  !> moving ground end).
  pure real(wp) function element_damping_power(scene, v, t) result(power)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: v(:)
    real(wp), intent(in), optional :: t
    integer :: j
    power = 0.0_wp
    if (present(t)) then
      do j = 1, scene%n_elements
        associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
          power = power + scene%element_c(j) * ((at_end(v, b) - at_end(v, a)) - anchor(scene, j, 1, t))**2
        end associate
      end do
      return
    end if
    do j = 1, scene%n_elements
      associate (a => scene%element_body(1, j), b => scene%element_body(2, j))
        power = power + scene%element_c(j) * (at_end(v, b) - at_end(v, a))**2
      end associate
    end do
  end function element_damping_power

  !> Power the moving ground ends put in through the elements at positions x + dx,
  !> velocities v, time t: the tension pulls the anchor toward the body, which moves at w'.
  pure real(wp) function element_drive_power(scene, x, dx, v, t) result(power)
    type(scene_type), intent(in) :: scene
    real(wp), intent(in) :: x(:), dx(:), v(:), t
    integer :: j
    power = 0.0_wp
    do j = 1, scene%n_elements
      if (scene%element_drive(j) == 0) cycle
      power = power - tension_of(scene, j, x, dx, v, t) * anchor(scene, j, 1, t)
    end do
  end function element_drive_power
end module impact1d_elements
