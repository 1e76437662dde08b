!> Linear springs and viscous dampers (docs/method.md, "Springs and dampers"): body 1 to the
!> ground, body 2 to the ground, and between the bodies along x2 - x1. Each element is
!> present only when the scene names it; a scene that names none has springs%present false
!> and the solver never calls this module.
!> A kernel of the pair, in lanes (impact1d_lanes): the three elements of two bodies written
!> out, so that the stepping loop computes them without a branch or an index. A one-body
!> scene has k1 alone (k2 and k12 are 0; its body 2 is the idle lane at 0).
module impact1d_springs
  use impact1d_kinds, only: wp
  use impact1d_lanes, only: max_lanes
  implicit none
  private
  public :: springs_type, n_elements

  !> Elements: 1 body 1 to the ground, 2 body 2 to the ground, 3 between the bodies.
  integer, parameter :: n_elements = 3

  type :: springs_type
    logical :: present = .false.                  !< any stiffness or damping named
    logical :: has_spring = .false., has_damper = .false.
    real(wp) :: k(n_elements) = 0.0_wp            !< (3) stiffness, N/m
    real(wp) :: rest(n_elements) = 0.0_wp         !< (3) x1_rest, x2_rest, d_rest
    real(wp) :: c(n_elements) = 0.0_wp            !< (3) damping, N s/m
    !> An upper bound of the fastest rate in the motion (rad/s), set once (set_frequency).
    real(wp) :: omega = 0.0_wp
  contains
    procedure :: add_force
    procedure :: add_force_rate
    procedure :: potential
    procedure :: damping_power
    procedure :: set_frequency
    procedure :: linear_part
  end type springs_type

contains

  !> Elongations of the three springs for positions x + dx (lanes): dx carries the low parts
  !> of compensated positions (and a stage's displacement), added after the large terms cancel.
  pure subroutine elongation(self, x, dx, e)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: x(max_lanes), dx(max_lanes)
    real(wp), intent(out) :: e(n_elements)
    e(1) = (x(1) - self%rest(1)) + dx(1)
    e(2) = (x(2) - self%rest(2)) + dx(2)
    e(3) = ((x(2) - x(1)) - self%rest(3)) + (dx(2) - dx(1))
  end subroutine elongation

  !> Rates of the three elongations (lanes).
  pure subroutine elongation_rate(v, r)
    real(wp), intent(in) :: v(max_lanes)
    real(wp), intent(out) :: r(n_elements)
    r(1) = v(1)
    r(2) = v(2)
    r(3) = v(2) - v(1)
  end subroutine elongation_rate

  !> f += the forces on the bodies at positions x + dx and velocities v.
  pure subroutine add_force(self, x, dx, v, f)
    class(springs_type), intent(in) :: self
    real(wp), dimension(max_lanes), intent(in) :: x, dx, v
    real(wp), intent(inout) :: f(max_lanes)
    real(wp) :: e(n_elements), r(n_elements), tension(n_elements)
    call elongation(self, x, dx, e)
    call elongation_rate(v, r)
    ! Tension of each element: what it pulls its ends together with.
    tension = self%k * e + self%c * r
    f(1) = f(1) + (-tension(1) + tension(3))
    f(2) = f(2) + (-tension(2) - tension(3))
  end subroutine add_force

  !> df += the rate of the spring forces at velocities v (the dampers' part needs the
  !> accelerations and is left out: it only tells which way a force exactly at a bound goes).
  pure subroutine add_force_rate(self, v, df)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: v(max_lanes)
    real(wp), intent(inout) :: df(max_lanes)
    real(wp) :: r(n_elements), rate(n_elements)
    call elongation_rate(v, r)
    rate = self%k * r
    df(1) = df(1) + (-rate(1) + rate(3))
    df(2) = df(2) + (-rate(2) - rate(3))
  end subroutine add_force_rate

  !> Potential energy stored in the springs at positions x + dx.
  pure real(wp) function potential(self, x, dx)
    class(springs_type), intent(in) :: self
    real(wp), dimension(max_lanes), intent(in) :: x, dx
    real(wp) :: e(n_elements)
    call elongation(self, x, dx, e)
    potential = 0.5_wp * sum(self%k * e**2)
  end function potential

  !> Power the dampers dissipate at velocities v.
  pure real(wp) function damping_power(self, v)
    class(springs_type), intent(in) :: self
    real(wp), intent(in) :: v(max_lanes)
    real(wp) :: r(n_elements)
    call elongation_rate(v, r)
    damping_power = sum(self%c * r**2)
  end function damping_power

  !> omega: the stiffest natural frequency and the fastest damping rate over the lightest
  !> mass (min_mass). Steps sample the mode's conditions at least 16 times per 2 pi of it.
  pure subroutine set_frequency(self, min_mass)
    class(springs_type), intent(inout) :: self
    real(wp), intent(in) :: min_mass
    real(wp) :: stiffness, damping
    stiffness = self%k(1) + self%k(2) + 2.0_wp * self%k(3)
    damping = self%c(1) + self%c(2) + 2.0_wp * self%c(3)
    self%omega = sqrt(stiffness / min_mass) + damping / min_mass
  end subroutine set_frequency

  !> Stiffness and damping matrices (K, C in M x'' + C x' + K x = f) of n bodies (1 or 2:
  !> a one-body scene has no body-2 or link element).
  pure subroutine linear_part(self, n, k, c)
    class(springs_type), intent(in) :: self
    integer, intent(in) :: n
    real(wp), intent(out) :: k(n, n), c(n, n)
    call assemble(self%k, k)
    call assemble(self%c, c)
  end subroutine linear_part

  !> The matrix of the three elements' coefficients (to the ground, to the ground, between).
  pure subroutine assemble(coefficient, matrix)
    real(wp), intent(in) :: coefficient(n_elements)
    real(wp), intent(out) :: matrix(:, :)
    matrix = 0.0_wp
    matrix(1, 1) = coefficient(1)
    if (size(matrix, 1) == 1) return
    matrix(2, 2) = coefficient(2) + coefficient(3)
    matrix(1, 1) = matrix(1, 1) + coefficient(3)
    matrix(1, 2) = -coefficient(3)
    matrix(2, 1) = -coefficient(3)
  end subroutine assemble
end module impact1d_springs
